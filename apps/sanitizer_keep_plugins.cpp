// Sanitizer builds only. Open MPI unloads its plugins (mca_*.so, dlclose) in
// MPI_Finalize, before LeakSanitizer runs at exit; the allocations they keep to
// the end then show stack frames in unmapped code, which no suppression can
// name (see the suppressions in petsc_session.cpp). This dlclose, defined in the
// executable, takes the place of libc's for every library: nothing is unloaded
// and the frames stay named. (No <dlfcn.h> here: its declaration differs.)
#if defined(__SANITIZE_ADDRESS__)
extern "C" int dlclose(void*) { return 0; }
#endif
