! test_fortran_mpi.f90 -- the Fortran binding's row-block calls with complex
! values in an MPI program (SPMD mode):
!
!     SILC_MODE=spmd mpirun -np P test_fortran_mpi
!
! Each rank puts only its rows (split as PETSc splits them) of a complex
! Helmholtz-like tridiagonal A (diagonal 2.5 + 0.5i, off-diagonals -1 + 0.1i,
! as test_fortran's: complex symmetric, strictly diagonally dominant) as a
! 1-based CSR block with global columns, and its rows of b = A xt for the
! exact solution xt = (1 + 2i, ...).  x = A \ b runs on MUMPS (zmumps) on the
! blocks, and each rank gets its rows of x back into a complex(8) array: they
! must start at the rank's own first row and match xt within 10 n eps
! cond_1(A), with cond_1(A) <= (|d| + 2|o|) / (|d| - 2|o|) (Varah's bound on
! ||A^-1||, A = A.').  A real array refuses the complex rows with the
! library's message; a complex array takes a real value's rows (imaginary
! parts 0).  Rank 0 prints "N passed, N failed" (the failures of every rank);
! every rank ends with error stop when anything failed anywhere.
program test_fortran_mpi
  use, intrinsic :: iso_c_binding, only: c_double, c_double_complex
  use mpi
  use silc
  use silc_checks
  implicit none
  integer, parameter :: n = 400
  complex(c_double_complex), parameter :: d = (2.5_c_double, 0.5_c_double), o = (-1.0_c_double, 0.1_c_double)
  integer :: rank, nranks, silc_r, silc_p, ierr, first, rows, got_first, i, j, k, counts(2)
  integer, allocatable :: rp(:), ci(:)
  complex(c_double_complex), allocatable :: vals(:), b(:), x(:)
  real(c_double), allocatable :: rx(:)
  real(c_double) :: err, bound
  real(c_double), parameter :: xt_max = sqrt(13.0_c_double) ! max_i |xt_i| = |3 +- 2i|

  call MPI_Init(ierr)
  call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierr)
  call MPI_Comm_size(MPI_COMM_WORLD, nranks, ierr)
  write (check_prefix, '(a, i0, a)') ' (rank ', rank, ')'
  rows = n / nranks + merge(1, 0, rank < mod(n, nranks))
  first = rank * (n / nranks) + min(rank, mod(n, nranks)) + 1

  ! This rank's rows of A (1-based local rowptr, global columns) and of b.
  allocate(rp(rows + 1), ci(3 * rows), vals(3 * rows), b(rows))
  k = 0
  rp(1) = 1
  do i = first, first + rows - 1
    b(i - first + 1) = 0
    do j = max(1, i - 1), min(n, i + 1)
      k = k + 1
      ci(k) = j
      vals(k) = merge(d, o, i == j)
      b(i - first + 1) = b(i - first + 1) + vals(k) * exact(j)
    end do
    rp(i - first + 2) = k + 1
  end do

  call check_ok(silc_init(), 'silc_init (SILC_MODE=spmd)')
  call check_ok(silc_rank(silc_r, silc_p), 'silc_rank')
  call check(silc_r == rank .and. silc_p == nranks, 'SILC runs on the MPI ranks (SILC_MODE=spmd)')
  call check_ok(silc_put_rows('A', first, rows, n, rp, ci, vals(1:k)), 'put_rows of a complex CSR block')
  call check_ok(silc_put_rows('b', first, b), 'put_rows of a complex vector block')
  call check_ok(silc_exec('x = solve(A, b, "backend = mumps")'), 'complex solve on MUMPS')

  bound = 10 * n * epsilon(1.0_c_double) * (abs(d) + 2 * abs(o)) / (abs(d) - 2 * abs(o))
  got_first = -1
  err = huge(err)
  call check_ok(silc_get_rows('x', got_first, x), 'get_rows of the complex solution')
  if (allocated(x)) then
    call check(got_first == first .and. size(x) == rows, 'the rank''s own rows of x')
    if (size(x) == rows) err = maxval(abs(x - [(exact(i), i = first, first + rows - 1)])) / xt_max
  end if
  call MPI_Allreduce(MPI_IN_PLACE, err, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD, ierr)
  call check(err <= bound, 'complex rows of x against the exact solution: error ' // &
             real_text(err) // ', bound ' // real_text(bound))
  if (rank == 0) print '(a, i0, a, es9.2, a, es9.2)', 'complex rows of x on ', nranks, &
    ' ranks: error ', err, ', bound 10 n eps cond_1 ', bound
  call check_fails(silc_get_rows('x', got_first, rx), '''x'' is complex', &
                   'get_rows of a complex value into a real array')

  call check_ok(silc_exec('r = real(x)'), 'r = real(x)')
  call check_ok(silc_get_rows('r', got_first, x), 'a real value''s rows into a complex array')
  if (allocated(x)) call check(size(x) == rows .and. all(aimag(x) == 0) .and. &
                               maxval(abs(real(x, c_double) - [(real(exact(i)), i = first, first + rows - 1)])) &
                               <= xt_max * bound, 'real rows, imaginary parts 0')
  call check_ok(silc_finalize(), 'silc_finalize')
  ! The main program's allocatables live until its end: freed here, so that
  ! LeakSanitizer (CI) sees nothing left.
  deallocate(rp, ci, vals, b)
  if (allocated(x)) deallocate(x)
  if (allocated(rx)) deallocate(rx)

  counts = [passed, failed]
  call MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_INTEGER, MPI_SUM, MPI_COMM_WORLD, ierr)
  if (rank == 0) print '(i0, a, i0, a)', counts(1), ' passed, ', counts(2), ' failed'
  call MPI_Finalize(ierr)
  if (counts(2) > 0) error stop 1

contains

  ! The exact solution's i-th entry (1-based).
  pure complex(c_double_complex) function exact(i)
    integer, intent(in) :: i
    exact = cmplx(1 + mod(i - 1, 3), 2 - mod(i - 1, 5), c_double_complex)
  end function exact

end program test_fortran_mpi
