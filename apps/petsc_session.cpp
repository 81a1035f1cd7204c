#include "petsc_session.h"

#include <petscsys.h>

#include "tspline/errors.h"

namespace tspline_app {

PetscSession::PetscSession() {
  if (PetscInitializeNoArguments() != 0) throw tspline::NumericalError("PETSc (MPI) initialization failed");
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
  PetscMPIInt r = 0, s = 1;
  MPI_Comm_rank(PETSC_COMM_WORLD, &r);
  MPI_Comm_size(PETSC_COMM_WORLD, &s);
  rank_ = r;
  size_ = s;
}

PetscSession::~PetscSession() {
  PetscPopErrorHandler();
  PetscFinalize();
}

}  // namespace tspline_app

#if defined(__SANITIZE_ADDRESS__)
// The tspline program's LeakSanitizer suppressions (one definition per program).
// Open MPI, hwloc and PETSc keep allocations to the end of the process (and
// Open MPI's plugins are dlopen'ed; sanitizer_keep_plugins.cpp keeps them
// mapped); so do GDAL/PROJ (driver registry, PROJ contexts) and
// Cairo/fontconfig (font caches), and Gmsh (the quad layouts' mesher, run in
// this process under the sanitizer: quad_mesher.cpp). LeakSanitizer would report them. Leaks whose
// stack passes through these libraries are suppressed; ours are not.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libgdal\nleak:libproj\nleak:libcairo\nleak:libfontconfig\nleak:libgmsh\n"
         "leak:libmpi\nleak:libopen-pal\nleak:libopen-rte\nleak:libhwloc\nleak:libpetsc\nleak:libHYPRE\n"
         "leak:mca_\nleak:libpmix\nleak:libevent\n"
         // One string of Open MPI's set-up (opal_asprintf): the fast unwinder
         // stops inside glibc's vasprintf, so its caller cannot be named. Our
         // code does not call vasprintf.
         "leak:__vasprintf_internal\n";
}
// Without the table of used suppressions on stderr (errors are one line).
extern "C" const char* __lsan_default_options() { return "print_suppressions=0"; }
#endif
