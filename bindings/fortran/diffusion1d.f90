! diffusion1d.f90 -- the 1-D diffusion example of examples/diffusion1d.c, in
! Fortran through the `silc` module: Crank-Nicolson for u_t = u_xx on [0, pi]
! with u(x, 0) = sin x and u = 0 at both ends, whose exact solution is
! e^{-t} sin x.
!
!     diffusion1d [N [steps [T [FILE]]]]   defaults: N = 100 interior points,
!                                          steps = 500 (dt = 1e-3), T = 0.5;
!                                          FILE: write the final u there, one
!                                          value a line, 17 digits
!
! The tridiagonal matrices A = I - dt/2 L and B = I + dt/2 L are assembled here
! as 1-based CSR and deposited once; u stays inside SILC between steps, each
! step being "b = B * u; u = A \ b", and only the final field comes back.  The
! error against the exact solution is dominated by the spatial error
! ~ T h^2 e^{-T} / 12 (2.4e-5 at the defaults); the program exits with status 1
! if it exceeds max(1e-4, 4 x that estimate), i.e. if the scheme went wrong.
! Set SILC_SERVER=tcp://host:port to run the same program against silcd.
! diffusion1d_mpi.f90 is the same run as an MPI program, each rank its rows.
program diffusion1d
  use, intrinsic :: iso_c_binding, only: c_double
  use, intrinsic :: iso_fortran_env, only: error_unit, int64
  use silc
  use diffusion1d_common
  implicit none
  real(c_double), parameter :: pi = acos(-1.0_c_double)
  integer :: n, steps, s, i
  real(c_double) :: t_end, dt, h, err, estimate, tol
  real(c_double), allocatable :: u(:), x(:)
  integer(int64) :: clock0, clock1, rate
  character(len=:), allocatable :: out_file

  n = 100
  steps = 500
  t_end = 0.5_c_double
  out_file = ''
  if (diff1d_parse_args(n, steps, t_end, out_file) /= 0) then
    write (error_unit, '(a)') 'usage: diffusion1d [N [steps [T [FILE]]]]   (N, steps positive integers, ' // &
      'T >= 0, FILE receives the final u)'
    stop 2
  end if
  dt = t_end / steps
  h = pi / (n + 1)
  allocate(u(n), x(n))
  x = [(i * h, i = 1, n)]
  u = sin(x)

  if (silc_init() /= 0) call die('silc_init')
  call system_clock(clock0, rate)
  if (put_shifted_laplacian('A', -dt / 2) /= 0) call die('silc_put_csr A')
  if (put_shifted_laplacian('B', dt / 2) /= 0) call die('silc_put_csr B')
  if (silc_put('u', u) /= 0) call die('silc_put u')
  do s = 1, steps
    if (silc_exec('b = B * u; u = A \ b') /= 0) call die('silc_exec')
  end do
  if (silc_get('u', u) /= 0) call die('silc_get u')
  call system_clock(clock1)
  if (silc_finalize() /= 0) call die('silc_finalize')

  err = maxval(abs(u - exp(-t_end) * sin(x)))
  estimate = t_end * h**2 * exp(-t_end) / 12
  tol = max(1.0e-4_c_double, 4 * estimate)
  write (*, '(a, i0, a, i0, 7a)') 'N=', n, ' steps=', steps, ' T=', diff1d_num(t_end), &
    ' dt=', diff1d_num(dt), ' time=', diff1d_num(real(clock1 - clock0, c_double) / rate), 's'
  write (*, '(a, es10.3, a, es10.3, a)') 'max error=', err, &
    ' (spatial error estimate T h^2 e^-T / 12 = ', estimate, ')'
  if (len(out_file) > 0) call write_field(out_file, u)
  deallocate(out_file)   ! a main program's allocatables are never freed for it
  deallocate(u, x)
  if (.not. (err <= tol)) then   ! written so that a NaN fails too
    write (error_unit, '(a, es10.3, a)') 'diffusion1d: error above the tolerance ', tol, &
      ': the scheme did not converge as it should'
    stop 1
  end if

contains

  ! Deposits I + c L, whole (diffusion1d_common.f90 assembles it).
  integer function put_shifted_laplacian(name, c) result(status)
    character(len=*), intent(in) :: name
    real(c_double), intent(in) :: c
    integer, allocatable :: rowptr(:), colind(:)
    real(c_double), allocatable :: values(:)
    call diff1d_laplacian_rows(n, h, c, 1, n, rowptr, colind, values)
    status = silc_put_csr(name, n, n, rowptr, colind, values)
  end function put_shifted_laplacian

  ! The field, one value a line with 17 significant digits (round-trip exact).
  subroutine write_field(path, v)
    character(len=*), intent(in) :: path
    real(c_double), intent(in) :: v(:)
    integer :: unit, ios
    open (newunit=unit, file=path, status='replace', action='write', iostat=ios)
    if (ios == 0) write (unit, '(es25.17e3)', iostat=ios) v
    if (ios == 0) close (unit, iostat=ios)
    if (ios /= 0) then
      write (error_unit, '(a)') 'diffusion1d: cannot write ' // path
      stop 1
    end if
  end subroutine write_field

  subroutine die(what)
    character(len=*), intent(in) :: what
    write (error_unit, '(a)') 'diffusion1d: ' // what // ' failed: ' // silc_errmsg()
    stop 1
  end subroutine die

end program diffusion1d
