# Tests of the Fortran binding (included from tests/CMakeLists.txt): the module's
# own test and the Fortran diffusion example, which exits 1 if its error exceeds
# the scheme's bound.  Both run embedded; the module's test runs against the
# fixture's silcd too (test_fortran_remote).  With MPI for Fortran, the SPMD example
# (diffusion1d_mpi.f90) runs under mpirun -np 2 and must print the serial
# example's summary and end with its field to 1e-12 relative, and
# test_fortran_mpi checks complex row blocks in and out under mpirun -np 2.
if(TARGET silc_fortran)
  # The checks both Fortran tests count with (one module, built once).
  add_library(silc_fortran_checks STATIC ${CMAKE_CURRENT_LIST_DIR}/silc_checks.f90)
  target_link_libraries(silc_fortran_checks PUBLIC silc_fortran)
  set_target_properties(silc_fortran_checks PROPERTIES Fortran_MODULE_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}/checks_mod)
  target_include_directories(silc_fortran_checks PUBLIC ${CMAKE_CURRENT_BINARY_DIR}/checks_mod)
  add_executable(test_fortran ${CMAKE_CURRENT_LIST_DIR}/test_fortran.f90)
  target_link_libraries(test_fortran PRIVATE silc_fortran_checks)
  if(CMAKE_Fortran_COMPILER_ID STREQUAL "GNU")
    # Round trips are checked for exact equality on purpose: nothing may change a bit.
    target_compile_options(test_fortran PRIVATE -Wno-compare-reals)
  endif()
  add_test(NAME test_fortran COMMAND test_fortran)
  add_test(NAME example_diffusion1d_fortran COMMAND diffusion1d_fortran)
  set_tests_properties(test_fortran example_diffusion1d_fortran PROPERTIES
    ENVIRONMENT "${SILC_TEST_ENV}" TIMEOUT 600)
  # The same test through libsilc's remote mode against the fixture's silcd
  # (complex values and every other call go over the protocol there).
  if(TARGET silcd)
    add_test(NAME test_fortran_remote COMMAND test_fortran)
    set_tests_properties(test_fortran_remote PROPERTIES ENVIRONMENT "${_remote_env}" TIMEOUT 120
                         FIXTURES_REQUIRED silcd)
  endif()

  if(TARGET diffusion1d_mpi_fortran AND MPIEXEC_EXECUTABLE)
    # sh -c SCRIPT sh MPIRUN SERIAL SPMD OUTDIR: both examples write their
    # final u (17 digits a value); the summaries must match but for time=, and
    # the fields must agree to 1e-12 in the max norm, relative to the serial one.
    set(_compare_mpi [=[
set -u
mpirun=$1 serial=$2 spmd=$3 out=$4
mkdir -p "$out" || exit 1
"$serial" 100 500 0.5 "$out/serial.txt" >"$out/serial.log" ||
    { cat "$out/serial.log"; echo "FAIL: diffusion1d_fortran failed"; exit 1; }
SILC_MODE=spmd "$mpirun" -np 2 "$spmd" 100 500 0.5 "$out/mpi.txt" >"$out/mpi.log" ||
    { cat "$out/mpi.log"; echo "FAIL: mpirun -np 2 diffusion1d_mpi_fortran failed"; exit 1; }
cat "$out/mpi.log"
want=$(sed 's/ time=[^ ]*//' "$out/serial.log")
got=$(sed 's/ time=[^ ]*//' "$out/mpi.log")
if [ "$got" != "$want" ]; then
    echo "FAIL: mpirun -np 2 printed"; echo "$got"; echo "the serial example printed"; echo "$want"
    exit 1
fi
awk 'NR == FNR { a[FNR] = $1 + 0; n = FNR; next }
     { m = FNR; d = $1 - a[FNR]; if (d < 0) d = -d; if (d > dmax) dmax = d
       v = a[FNR] < 0 ? -a[FNR] : a[FNR]; if (v > vmax) vmax = v }
     END { if (n == 0 || m != n) { print "FAIL: " n " serial values, " m " from mpirun"; exit 1 }
           printf "max |u_mpi - u_serial| = %.3e, relative %.3e (limit 1e-12)\n", dmax, dmax / vmax
           if (!(dmax <= 1e-12 * vmax)) { print "FAIL: the fields differ"; exit 1 } }' \
    "$out/serial.txt" "$out/mpi.txt"
]=])
    add_test(NAME example_diffusion1d_fortran_mpi
             COMMAND sh -c "${_compare_mpi}" sh ${MPIEXEC_EXECUTABLE} $<TARGET_FILE:diffusion1d_fortran>
                     $<TARGET_FILE:diffusion1d_mpi_fortran> ${CMAKE_CURRENT_BINARY_DIR}/diffusion1d-fortran-mpi)
    set_tests_properties(example_diffusion1d_fortran_mpi PROPERTIES
      ENVIRONMENT "${SILC_TEST_ENV};OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_rmaps_base_oversubscribe=1"
      TIMEOUT 120 RUN_SERIAL TRUE)

    # The row-block calls with complex values under mpirun -np 2: each rank
    # puts its rows of a complex tridiagonal, MUMPS solves on the blocks, and
    # each rank's rows of x must match the exact solution (test_fortran_mpi.f90).
    # MPI::MPI_Fortran is found here again: imported targets are per directory.
    find_package(MPI COMPONENTS Fortran QUIET)
    add_executable(test_fortran_mpi ${CMAKE_CURRENT_LIST_DIR}/test_fortran_mpi.f90)
    target_link_libraries(test_fortran_mpi PRIVATE silc_fortran_checks silc_mpi MPI::MPI_Fortran)
    if(CMAKE_Fortran_COMPILER_ID STREQUAL "GNU")
      target_compile_options(test_fortran_mpi PRIVATE -Wno-compare-reals) # imaginary parts exactly 0
    endif()
    add_test(NAME test_fortran_mpi COMMAND ${MPIEXEC_EXECUTABLE} -np 2 $<TARGET_FILE:test_fortran_mpi>)
    set_tests_properties(test_fortran_mpi PROPERTIES
      ENVIRONMENT "${SILC_TEST_ENV};SILC_MODE=spmd;OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_rmaps_base_oversubscribe=1"
      TIMEOUT 120 RUN_SERIAL TRUE)
  else()
    message(STATUS "SILC: Fortran MPI test skipped (diffusion1d_mpi_fortran or mpirun not built/found)")
  endif()
endif()
