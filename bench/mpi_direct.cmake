# bench/mpi_direct (included from bench/CMakeLists.txt): the baseline for the
# MPI server bench -- the same PETSc solves (hypre CG, GMRES + block Jacobi,
# MUMPS LU) called directly by a small MPI program, no SILC.  Built only when
# PETSc and MPI are found, found the way plugin-petsc finds them: PETSc's
# pkg-config module (PETSc) lacks MPI's include path, which comes from
# find_package(MPI) through MPI::MPI_C.  Not a test; run it with mpirun.
pkg_check_modules(BENCH_PETSC IMPORTED_TARGET PETSc>=3.15)
find_package(MPI COMPONENTS C QUIET)
set(_mpi_direct_missing "")
if(NOT BENCH_PETSC_FOUND)
  list(APPEND _mpi_direct_missing "PETSc >= 3.15 (pkg-config module PETSc)")
endif()
if(NOT MPI_C_FOUND)
  list(APPEND _mpi_direct_missing "MPI for C")
endif()
if(_mpi_direct_missing)
  string(REPLACE ";" ", " _mpi_direct_missing "${_mpi_direct_missing}")
  message(STATUS "SILC: bench/mpi_direct skipped: ${_mpi_direct_missing} not found (apt-get install petsc-dev)")
else()
  add_executable(mpi_direct mpi_direct.c)
  target_link_libraries(mpi_direct PRIVATE PkgConfig::BENCH_PETSC MPI::MPI_C)
endif()
