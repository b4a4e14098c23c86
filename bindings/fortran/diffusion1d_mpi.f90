! diffusion1d_mpi.f90 -- diffusion1d.f90 as an MPI program: the same
! Crank-Nicolson run for u_t = u_xx on [0, pi] (u(x, 0) = sin x, u = 0 at both
! ends, exact solution e^{-t} sin x), with the matrices and the field split by
! rows over the ranks and SILC running on every rank (SPMD mode).
!
!     SILC_MODE=spmd mpirun -np P diffusion1d_mpi [N [steps [T [FILE]]]]
!         defaults as diffusion1d: N = 100, steps = 500, T = 0.5; FILE: rank 0
!         writes the final u there, one value a line, 17 digits
!
! With SILC_MODE=spmd (and the program linked with libsilc_mpi) silc_init()
! opens the default context over MPI_COMM_WORLD.  No rank ever holds a whole
! matrix: each assembles only its rows of A = I - dt/2 L and B = I + dt/2 L
! (1-based CSR with global column numbers) and of the initial field, split as
! PETSc splits N rows (the first mod(N, P) ranks get one row more), and the
! loop is diffusion1d's, every call collective:
!
!     silc_put_rows('A', first, rows, N, rowptr, colind, values); 'B'; 'u'
!     each step: silc_exec('b = B * u; u = A \ b')
!     silc_get_rows('u', first, u)
!
! Rank 0 prints diffusion1d's summary lines (the maximum error is reduced over
! the ranks with MPI_Allreduce) and, given FILE, gathers the field with
! MPI_Gatherv to write it -- the only place the whole field is in one process.
! The exit status is diffusion1d's: 1 if the error exceeds the scheme's bound.
! Under mpirun -np 1 (or without mpirun) SILC_MODE=spmd is not needed.
program diffusion1d_mpi
  use, intrinsic :: iso_c_binding, only: c_double
  use, intrinsic :: iso_fortran_env, only: error_unit
  use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
  use mpi
  use silc
  use diffusion1d_common
  implicit none
  real(c_double), parameter :: pi = acos(-1.0_c_double)
  integer :: n, steps, s, i, ierr, rank, nranks, silc_r, silc_p, first, rows, got_first
  real(c_double) :: t_end, dt, h, err, local_err, estimate, tol, t0, t1
  real(c_double), allocatable :: u(:), x(:)
  character(len=:), allocatable :: out_file

  call MPI_Init(ierr)
  call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierr)
  call MPI_Comm_size(MPI_COMM_WORLD, nranks, ierr)

  ! Every rank reads the same command line; rank 0 reports a bad one.
  n = 100
  steps = 500
  t_end = 0.5_c_double
  out_file = ''
  if (diff1d_parse_args(n, steps, t_end, out_file) /= 0) then
    if (rank == 0) write (error_unit, '(a)') 'usage: SILC_MODE=spmd mpirun -np P diffusion1d_mpi ' // &
      '[N [steps [T [FILE]]]]   (N, steps positive integers, T >= 0, FILE receives the final u)'
    call MPI_Finalize(ierr)
    stop 2
  end if
  dt = t_end / steps
  h = pi / (n + 1)
  rows = n / nranks + merge(1, 0, rank < mod(n, nranks))
  first = rank * (n / nranks) + min(rank, mod(n, nranks)) + 1
  allocate(x(rows))
  x = [(i * h, i = first, first + rows - 1)]
  u = sin(x)

  if (silc_init() /= 0) call die('silc_init')
  if (silc_rank(silc_r, silc_p) /= 0) call die('silc_rank')
  if (silc_r /= rank .or. silc_p /= nranks) then
    if (rank == 0) write (error_unit, '(a, i0, a, i0, a)') 'diffusion1d_mpi: SILC runs on ', silc_p, &
      ' rank(s), MPI on ', nranks, ': set SILC_MODE=spmd'
    call MPI_Finalize(ierr)
    stop 1
  end if
  call MPI_Barrier(MPI_COMM_WORLD, ierr)
  t0 = MPI_Wtime()
  if (put_shifted_laplacian_rows('A', -dt / 2) /= 0) call die('silc_put_rows A')
  if (put_shifted_laplacian_rows('B', dt / 2) /= 0) call die('silc_put_rows B')
  if (silc_put_rows('u', first, u) /= 0) call die('silc_put_rows u')
  do s = 1, steps
    if (silc_exec('b = B * u; u = A \ b') /= 0) call die('silc_exec')
  end do
  if (silc_get_rows('u', got_first, u) /= 0) call die('silc_get_rows u')
  call MPI_Barrier(MPI_COMM_WORLD, ierr)   ! the time of the slowest rank
  t1 = MPI_Wtime()
  if (silc_finalize() /= 0) call die('silc_finalize')
  ! u was computed from the rows deposited, so it keeps them.
  if (got_first /= first .or. size(u) /= rows) then
    write (error_unit, '(a, i0, a, i0, a, i0, a, i0, a, i0)') 'diffusion1d_mpi: rank ', rank, &
      ' got rows ', got_first, '..', got_first + size(u) - 1, ' of u back, not ', first, '..', &
      first + rows - 1
    call MPI_Abort(MPI_COMM_WORLD, 1, ierr)
  end if

  local_err = 0
  if (rows > 0) local_err = maxval(abs(u - exp(-t_end) * sin(x)))
  if (any(ieee_is_nan(u))) local_err = huge(local_err)   ! a NaN must fail
  call MPI_Allreduce(local_err, err, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD, ierr)
  estimate = t_end * h**2 * exp(-t_end) / 12
  tol = max(1.0e-4_c_double, 4 * estimate)
  if (rank == 0) then
    write (*, '(a, i0, a, i0, 7a)') 'N=', n, ' steps=', steps, ' T=', diff1d_num(t_end), &
      ' dt=', diff1d_num(dt), ' time=', diff1d_num(t1 - t0), 's'
    write (*, '(a, es10.3, a, es10.3, a)') 'max error=', err, &
      ' (spatial error estimate T h^2 e^-T / 12 = ', estimate, ')'
  end if
  if (len(out_file) > 0) call write_field(out_file)
  deallocate(out_file)   ! a main program's allocatables are never freed for it
  deallocate(u, x)
  call MPI_Finalize(ierr)
  if (.not. (err <= tol)) then
    if (rank == 0) write (error_unit, '(a, es10.3, a)') 'diffusion1d_mpi: error above the tolerance ', &
      tol, ': the scheme did not converge as it should'
    stop 1
  end if

contains

  ! Deposits this rank's rows first..first+rows-1 of I + c L (global column
  ! numbers; diffusion1d_common.f90 assembles them).
  integer function put_shifted_laplacian_rows(name, c) result(status)
    character(len=*), intent(in) :: name
    real(c_double), intent(in) :: c
    integer, allocatable :: rowptr(:), colind(:)
    real(c_double), allocatable :: values(:)
    call diff1d_laplacian_rows(n, h, c, first, rows, rowptr, colind, values)
    status = silc_put_rows(name, first, rows, n, rowptr, colind, values)
  end function put_shifted_laplacian_rows

  ! Gathers the ranks' blocks of u, in rank order, on rank 0, which writes
  ! them as diffusion1d does.
  subroutine write_field(path)
    character(len=*), intent(in) :: path
    real(c_double), allocatable :: whole(:)
    integer, allocatable :: counts(:), displs(:)
    integer :: r, unit, ios
    allocate(whole(merge(n, 0, rank == 0)), counts(nranks), displs(nranks))
    do r = 0, nranks - 1
      counts(r + 1) = n / nranks + merge(1, 0, r < mod(n, nranks))
      displs(r + 1) = r * (n / nranks) + min(r, mod(n, nranks))
    end do
    call MPI_Gatherv(u, rows, MPI_DOUBLE_PRECISION, whole, counts, displs, MPI_DOUBLE_PRECISION, &
                     0, MPI_COMM_WORLD, ierr)
    ios = 0
    if (rank == 0) then
      open (newunit=unit, file=path, status='replace', action='write', iostat=ios)
      if (ios == 0) write (unit, '(es25.17e3)', iostat=ios) whole
      if (ios == 0) close (unit, iostat=ios)
      if (ios /= 0) write (error_unit, '(a)') 'diffusion1d_mpi: cannot write ' // path
    end if
    call MPI_Bcast(ios, 1, MPI_INTEGER, 0, MPI_COMM_WORLD, ierr)   ! all ranks exit alike
    if (ios /= 0) then
      call MPI_Finalize(ierr)
      stop 1
    end if
  end subroutine write_field

  ! SILC's calls are collective and fail on every rank together, so every
  ! rank comes here: rank 0 reports (the message names the rank at fault).
  subroutine die(what)
    character(len=*), intent(in) :: what
    if (rank == 0) write (error_unit, '(a)') 'diffusion1d_mpi: ' // what // ' failed: ' // silc_errmsg()
    call MPI_Finalize(ierr)
    stop 1
  end subroutine die

end program diffusion1d_mpi
