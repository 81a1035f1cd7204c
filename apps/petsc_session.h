#pragma once
// RAII guard of PETSc (and MPI) for the commands that use the PETSc module
// (tspline/petsc_solver.h): PetscInitialize on construction, PetscFinalize on
// destruction. Options come from the environment variable PETSC_OPTIONS only
// (the command line belongs to CLI11). PETSc's error handler is replaced by one
// that only returns the error code: the module turns it into one exception and
// main() prints one line.
namespace tspline_app {

class PetscSession {
 public:
  PetscSession();
  ~PetscSession();
  PetscSession(const PetscSession&) = delete;
  PetscSession& operator=(const PetscSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  int rank_ = 0, size_ = 1;
};

}  // namespace tspline_app
