! clients_fortran.f90 -- the Fortran binding (through libsilc's remote mode)
! as clients.py drives it against its fake silcd: SILC_SERVER names the fake
! server, silc_get_csr('A') receives its hostile CSR reply, and the program
! prints "OK csr ..." or "ERROR silc: <silc_errmsg()>" and ends by itself
! (status 0): a bad reply is an error code and a message, never a crash.
program clients_fortran
  use silc
  implicit none
  integer :: m, n
  integer, allocatable :: rowptr(:), colind(:)
  real(8), allocatable :: values(:)
  if (silc_init() /= 0) then
    print '(a)', 'ERROR silc: ' // silc_errmsg()
    stop
  end if
  if (silc_get_csr('A', m, n, rowptr, colind, values) /= 0) then
    print '(a)', 'ERROR silc: ' // silc_errmsg()
  else
    print '(a, i0, a, i0)', 'OK csr ', m, 'x', n
  end if
  if (silc_finalize() /= 0) print '(a)', 'finalize: ' // silc_errmsg()
end program clients_fortran
