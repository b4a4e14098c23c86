! silc_checks.f90 -- the checks the Fortran tests share: counts of passed and
! failed checks, as the C tests keep them (tests/check.h), a check of a
! binding call's status and of its error message, and a number as text for
! messages.  An MPI test names its rank in failures through check_prefix.
module silc_checks
  use, intrinsic :: iso_c_binding, only: c_double
  use silc, only: silc_errmsg
  implicit none
  private
  public :: passed, failed, check_prefix, check, check_ok, check_fails, real_text

  integer :: passed = 0, failed = 0
  !> Printed after FAIL, e.g. ' (rank 1)'; empty by default.
  character(len=32) :: check_prefix = ''

contains

  subroutine check(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (ok) then
      passed = passed + 1
    else
      failed = failed + 1
      print '(a)', 'FAIL' // trim(check_prefix) // ': ' // what
    end if
  end subroutine check

  !> Passes when status is 0; a failure shows the library's message.
  subroutine check_ok(status, what)
    integer, intent(in) :: status
    character(len=*), intent(in) :: what
    if (status == 0) then
      call check(.true., what)
    else
      call check(.false., what // ': ' // silc_errmsg())
    end if
  end subroutine check_ok

  !> Passes when status is non-zero with a non-empty message containing part.
  subroutine check_fails(status, part, what)
    integer, intent(in) :: status
    character(len=*), intent(in) :: part, what
    character(len=:), allocatable :: msg
    msg = silc_errmsg()
    if (status == 0) then
      call check(.false., what // ' should fail but returned 0')
    else
      call check(len(msg) > 0 .and. index(msg, part) > 0, what // ' fails with a message containing "' &
                 // part // '": ' // msg)
    end if
  end subroutine check_fails

  pure function real_text(x) result(s)
    real(c_double), intent(in) :: x
    character(len=:), allocatable :: s
    character(len=32) :: buf
    write (buf, '(es12.4)') x
    s = trim(adjustl(buf))
  end function real_text

end module silc_checks
