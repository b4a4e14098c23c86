! consumer.f90 -- a user's Fortran program against an installed SILC (the
! module `silc` through find_package(SILC)): solves a small dense system and
! checks the answer; exit status 1 if it is wrong.
program consumer
  use, intrinsic :: iso_c_binding, only: c_double
  use silc
  implicit none
  real(c_double) :: a(2, 2), b(2), x(2)
  a = reshape([4.0_c_double, 1.0_c_double, 1.0_c_double, 3.0_c_double], [2, 2])
  b = [5.0_c_double, 4.0_c_double]   ! a * [1, 1]
  if (silc_init() /= 0 .or. silc_put('A', a) /= 0 .or. silc_put('b', b) /= 0 .or. &
      silc_exec('x = A \ b') /= 0 .or. silc_get('x', x) /= 0) then
    print '(a)', 'consumer_f: ' // silc_errmsg()
    stop 1
  end if
  print '(a, es9.2)', 'consumer_f: x = A \ b off by ', maxval(abs(x - 1))
  if (silc_finalize() /= 0 .or. maxval(abs(x - 1)) > 1e-14_c_double) stop 1
end program consumer
