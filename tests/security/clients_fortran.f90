! clients_fortran.f90 -- the Fortran binding (through libsilc's remote mode)
! as clients.py drives it against its fake silcd: SILC_SERVER names the fake
! server, and each call on the command line after the URL runs once:
! get:NAME is silc_get_csr (real values: a plain GET), getc:NAME silc_get of
! a 2x2 complex(8) array (GET_COMPLEX).  It prints "OK ..." or "ERROR silc:
! <silc_errmsg()>" per call and ends by itself (status 0): a bad reply is an
! error code and a message, never a crash.
program clients_fortran
  use silc
  implicit none
  integer :: m, n, k, status
  integer, allocatable :: rowptr(:), colind(:)
  real(8), allocatable :: values(:)
  complex(8) :: z(2, 2)
  character(len=256) :: arg
  if (silc_init() /= 0) then
    print '(a)', 'ERROR silc: ' // silc_errmsg()
    stop
  end if
  do k = 2, command_argument_count()
    call get_command_argument(k, arg)
    if (arg(1:5) == 'getc:') then
      status = silc_get(trim(arg(6:)), z)
      if (status == 0) print '(a)', 'OK complex dense 2x2'
    else
      status = silc_get_csr(trim(arg(5:)), m, n, rowptr, colind, values)
      if (status == 0) print '(a, i0, a, i0)', 'OK csr ', m, 'x', n
    end if
    if (status /= 0) print '(a)', 'ERROR silc: ' // silc_errmsg()
  end do
  if (silc_finalize() /= 0) print '(a)', 'finalize: ' // silc_errmsg()
end program clients_fortran
