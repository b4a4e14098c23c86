# bench/mpi (included from bench/CMakeLists.txt): SILC over MPI -- the SPMD
# mode, a client of `silcd --mpi`, and embedded SILC -- on the problems of
# bench/mpi_direct, for bench/mpi.sh to compare with it.  Built only when
# libsilc_mpi (MPI) and PETSc exist, since its point is the comparison with
# the PETSc/MUMPS baseline.  Not a test.
if(TARGET silc_mpi AND NOT SILC_PETSC_MISSING)
  add_executable(mpi mpi.c)
  target_link_libraries(mpi PRIVATE silc_diffusion silc_mpi MPI::MPI_C)
endif()
