! test_fortran.f90 -- tests of the Fortran binding (module silc): scalars,
! vectors, dense 2-D arrays in column-major order, 1-based CSR in both integer
! kinds, shape checks on silc_get, error statuses with their messages, and the
! row-block calls of MPI programs on one process (silc_rank, silc_put_rows,
! silc_get_rows: the block is the whole value, first row 1), and complex(8)
! values through the same generics (a complex tridiagonal solve against its
! exact solution, bit-exact round trips, a real array refusing a complex
! value), the row-block calls included (complex blocks in, complex rows out,
! a real array refusing a complex value's rows; under mpirun -np 2:
! test_fortran_mpi.f90).
! Prints "N passed, N failed" as its last line, like the C tests (tests/check.h),
! and ends with error stop when anything failed.  Runs embedded, or remote when
! SILC_SERVER is set.
program test_fortran
  use, intrinsic :: iso_c_binding, only: c_double, c_double_complex, c_int64_t
  use silc
  use silc_checks
  implicit none

  call check_ok(silc_init(), 'silc_init')
  call test_scalars()
  call test_vectors()
  call test_dense()
  call test_csr()
  call test_csr_int64()
  call test_csr_mistakes()
  call test_errors()
  call test_rows()
  call test_complex()
  call test_rows_complex()
  call check_ok(silc_finalize(), 'silc_finalize')
  call check_fails(silc_exec('x = 1'), '', 'exec after silc_finalize')
  call test_rows_closed()

  print '(i0, a, i0, a)', passed, ' passed, ', failed, ' failed'
  if (failed > 0) error stop 1

contains

  ! Each status is taken into a variable before anything reads what the call
  ! defined: Fortran does not fix the order in which operands are evaluated.

  subroutine test_scalars()
    real(c_double) :: c
    c = -1
    call check_ok(silc_put('a', 2.5_c_double), 'put scalar')
    call check_ok(silc_exec('c = a * 3 + 1'), 'exec on a scalar')
    call check_ok(silc_get('c', c), 'get scalar')
    call check_near(c, 8.5_c_double, 0.0_c_double, 'scalar round trip through c = a * 3 + 1')
  end subroutine test_scalars

  subroutine test_vectors()
    real(c_double) :: v(4) = [1, -2, 3, 5], w(4), short(3), strided(8)
    real(c_double), allocatable :: r(:)
    integer :: m, n
    call check_ok(silc_put('v', v), 'put vector')
    call check_ok(silc_get_shape('v', m, n), 'get_shape v')
    call check(m == 4 .and. n == 1, 'a 1-D array is deposited as a 4x1 vector')
    call check_ok(silc_exec("w = 2 * v; s = v' * v"), 'exec on vectors')
    w = 0
    call check_ok(silc_get('w', w), 'get vector')
    call check(all(w == 2 * v), 'vector round trip through w = 2 * v')

    ! A row vector fits a 1-D array too; the array is allocated from the shape.
    call check_ok(silc_exec("r = v'"), 'transpose')
    call check_ok(silc_get_shape('r', m, n), 'get_shape r')
    call check(m == 1 .and. n == 4, 'shape of a row vector')
    allocate(r(m * n))
    call check_ok(silc_get('r', r), 'get a 1x4 row vector into a 1-D array')
    call check(all(r == v), 'row vector values')

    ! Non-contiguous sections go in and come out through the same generic.
    strided = 0
    strided(1:8:2) = v
    call check_ok(silc_put('p', strided(1:8:2)), 'put a strided section')
    strided = 0
    call check_ok(silc_get('p', strided(2:8:2)), 'get into a strided section')
    call check(all(strided(2:8:2) == v) .and. all(strided(1:7:2) == 0), 'strided section round trip')

    ! The caller's array must have the value's size, and stays untouched if not.
    short = 7
    call check_fails(silc_get('w', short), '4x1', 'get into a too short array')
    call check_fails(silc_get('w', short), 'size 3', 'get into a too short array')
    call check(all(short == 7), 'a failed get leaves the array unchanged')
    call check_fails(silc_get('s', short), '1x1', 'a scalar into a 3-element array')
  end subroutine test_vectors

  subroutine test_dense()
    real(c_double) :: x(2, 3), y(2, 3), col(2), xt(3, 2), e2(3) = [0, 1, 0]
    real(c_double) :: corner
    integer :: i, j
    do j = 1, 3
      do i = 1, 2
        x(i, j) = 10 * i + j
      end do
    end do
    call check_ok(silc_put('X', x), 'put dense 2x3')
    call check_ok(silc_put('e2', e2), 'put e2')
    y = 0
    call check_ok(silc_get('X', y), 'get dense 2x3')
    call check(all(y == x), 'dense round trip')
    ! Column-major with no transposition: X * e2 is Fortran's x(:, 2), and
    ! X[2, 3] is x(2, 3).
    call check_ok(silc_exec("c2 = X * e2; x23 = X[2, 3]; Xt = X'"), 'exec on X')
    call check_ok(silc_get('c2', col), 'get c2')
    call check(all(col == x(:, 2)), 'X * e2 is column 2')
    call check_ok(silc_get('x23', corner), 'get x23')
    call check(corner == x(2, 3), 'X[2, 3] is x(2, 3)')
    call check_ok(silc_get('Xt', xt), 'get Xt')
    call check(all(xt == transpose(x)), "X' is transpose(x)")
    call check_fails(silc_get('X', xt), '3x2', 'a 2x3 value into a 3x2 array')
  end subroutine test_dense

  ! A = [4 -1 0; -1 4 -1; 0 -1 4] with the columns of row 2 given out of order
  ! (the library sorts them); x = [1 2 3] solves A x = [2 4 10].
  subroutine test_csr()
    integer :: rowptr(4) = [1, 3, 6, 8], colind(7) = [1, 2, 3, 1, 2, 2, 3]
    real(c_double) :: values(7) = [4, -1, -1, -1, 4, -1, 4], b(3) = [2, 4, 10], x(3), full(3, 3)
    integer, allocatable :: rp(:), ci(:)
    real(c_double), allocatable :: vals(:)
    integer :: m, n
    call check_ok(silc_put_csr('A', 3, 3, rowptr, colind, values), 'put_csr')
    call check_ok(silc_put('b', b), 'put b')
    call check_ok(silc_exec('x = A \ b'), 'solve with 1-based CSR')
    x = 0
    call check_ok(silc_get('x', x), 'get x')
    call check(maxval(abs(x - [1, 2, 3])) < 1e-12_c_double, 'A \ b = [1 2 3]')

    ! Back out as a dense array and as 1-based CSR (rows sorted by the library).
    call check_ok(silc_get('A', full), 'CSR into a 2-D array')
    call check(all(full(1, :) == [4, -1, 0]) .and. all(full(2, :) == [-1, 4, -1]) &
               .and. all(full(3, :) == [0, -1, 4]), 'CSR to dense puts each entry in place')
    call check_ok(silc_get_csr('A', m, n, rp, ci, vals), 'get_csr')
    call check(m == 3 .and. n == 3 .and. size(rp) == 4 .and. size(ci) == 7 .and. size(vals) == 7, &
               'get_csr sizes')
    if (size(rp) == 4 .and. size(ci) == 7 .and. size(vals) == 7) then
      call check(all(rp == rowptr) .and. all(ci == [1, 2, 1, 2, 3, 2, 3]) &
                 .and. all(vals == [4, -1, -1, 4, -1, -1, 4]), 'get_csr gives 1-based sorted CSR')
    end if
    call check_fails(silc_get_csr('X', m, n, rp, ci, vals), 'dense', 'get_csr of a dense value')

    ! An empty row is fine.
    call check_ok(silc_put_csr('E', 2, 2, [1, 1, 2], [2], [5.0_c_double]), 'CSR with an empty row')
    call check_ok(silc_get('E', full(1:2, 1:2)), 'get E into a section')
    call check(all(full(1:2, 1:2) == reshape([0, 0, 0, 5], [2, 2])), 'empty row round trip')
  end subroutine test_csr

  subroutine test_csr_int64()
    integer(c_int64_t) :: rowptr(3) = [1_c_int64_t, 2_c_int64_t, 4_c_int64_t]
    integer(c_int64_t) :: colind(3) = [1_c_int64_t, 1_c_int64_t, 2_c_int64_t]
    integer(c_int64_t) :: m, n
    integer(c_int64_t), allocatable :: rp(:), ci(:)
    real(c_double) :: values(3) = [2, 1, 3], x(2)
    real(c_double), allocatable :: vals(:)
    ! [2 0; 1 3] y = [2; 7] gives y = [1; 2].
    call check_ok(silc_put_csr('L', 2_c_int64_t, 2_c_int64_t, rowptr, colind, values), &
                  'put_csr int64')
    call check_ok(silc_put('f', [2.0_c_double, 7.0_c_double]), 'put f')
    call check_ok(silc_exec('y = L \ f'), 'solve with int64 CSR')
    call check_ok(silc_get('y', x), 'get y')
    call check(maxval(abs(x - [1, 2])) < 1e-14_c_double, 'L \ f = [1 2]')
    call check_ok(silc_get_csr('L', m, n, rp, ci, vals), 'get_csr int64')
    call check(m == 2 .and. n == 2 .and. all(rp == rowptr) .and. all(ci == colind) &
               .and. all(vals == values), 'int64 get_csr round trip')
  end subroutine test_csr_int64

  subroutine test_csr_mistakes()
    real(c_double) :: v(3) = 1
    call check_fails(silc_put_csr('Z', 2, 2, [0, 1, 2], [0, 1], v), '1-based', '0-based rowptr')
    call check_fails(silc_put_csr('Z', 2, 2, [1, 2, 3], [1, 3], v), 'colind(2) = 3', &
                     'column 3 of 2')
    call check_fails(silc_put_csr('Z', 2, 2, [1, 3], [1, 2], v), 'm+1', 'short rowptr')
    call check_fails(silc_put_csr('Z', 2, 2, [1, 3, 2], [1, 2], v), 'decreases', &
                     'decreasing rowptr')
    call check_fails(silc_put_csr('Z', 1, 2, [1, 5], [1, 2], v), 'entries', 'rowptr past colind')
    call check_fails(silc_put_csr('Z', 1, 2, [1, 3], [2, 2], v), 'row 1 has column 2 twice', &
                     'duplicate column')
    call check_fails(silc_exec('z = Z'), 'Z', 'no failed put left Z behind')
  end subroutine test_csr_mistakes

  subroutine test_errors()
    real(c_double) :: x
    character(len=:), allocatable :: msg
    call check_fails(silc_exec('y = nosuchname + 1'), 'nosuchname', 'undefined name')
    call check_fails(silc_exec('y = (1 + '), '', 'syntax error')
    msg = silc_errmsg()
    call check(index(msg, 'nosuchname') == 0, 'a syntax error has its own message: ' // msg)
    call check_fails(silc_get('nosuchname', x), 'nosuchname', 'get of an undefined name')
    call check_ok(silc_exec('ok = 1'), 'the context works after errors')
    ! Names from fixed-length variables lose their trailing blanks.
    x = 0
    call check_ok(silc_get('ok' // repeat(' ', 10), x), 'a name with trailing blanks')
    call check(x > 0.5_c_double, 'value fetched by a blank-padded name')
  end subroutine test_errors

  ! Complex values (issue 31).  A Helmholtz-like complex tridiagonal A
  ! (diagonal 2.5 + 0.5i, off-diagonals -1 + 0.1i: complex symmetric and
  ! strictly diagonally dominant) with exact solution xt = (1 + 2i, ...):
  ! b = A xt, and x = A \ b must match xt within 10 n eps cond_1(A), where
  ! cond_1(A) <= ||A||_1 / min_i (|a_ii| - sum_j/=i |a_ij|) (Varah's bound on
  ! ||A^-1||, rows and columns alike since A = A.').
  subroutine test_complex()
    integer, parameter :: n = 40
    complex(c_double_complex), parameter :: d = (2.5_c_double, 0.5_c_double), &
                                            o = (-1.0_c_double, 0.1_c_double)
    integer :: rp(n + 1), ci(3 * n), i, j, k, m2, n2
    complex(c_double_complex) :: vals(3 * n), xt(n), b(n), x(n), z(2, 3), zt(3, 2), zback(2, 3), w
    complex(c_double_complex), allocatable :: gv(:)
    integer, allocatable :: grp(:), gci(:)
    real(c_double) :: bound, err, rz(2, 3)
    real(c_double), allocatable :: rvals(:)
    integer(c_int64_t) :: bits(6), bits_back(6)

    k = 0
    rp(1) = 1
    do i = 1, n
      do j = max(1, i - 1), min(n, i + 1)
        k = k + 1
        ci(k) = j
        vals(k) = merge(d, o, i == j)
      end do
      rp(i + 1) = k + 1
      xt(i) = cmplx(1 + mod(i - 1, 3), 2 - mod(i - 1, 5), c_double_complex)
    end do
    do i = 1, n
      b(i) = sum(vals(rp(i):rp(i + 1) - 1) * xt(ci(rp(i):rp(i + 1) - 1)))
    end do
    call check_ok(silc_put_csr('Az', n, n, rp, ci, vals(1:k)), 'put complex CSR')
    call check_ok(silc_put('bz', b), 'put a complex vector')
    call check_ok(silc_exec('xz = Az \ bz'), 'complex sparse solve')
    x = 0
    call check_ok(silc_get('xz', x), 'get a complex vector')
    bound = 10 * n * epsilon(1.0_c_double) * (abs(d) + 2 * abs(o)) / (abs(d) - 2 * abs(o))
    err = maxval(abs(x - xt)) / maxval(abs(xt))
    call check(err <= bound, 'complex solve against the exact solution: error ' // real_text(err) // &
               ', bound ' // real_text(bound))
    call check_ok(silc_get_shape('xz', m2, n2), 'get_shape of a complex value')
    call check(m2 == n .and. n2 == 1, 'shape of a complex vector')

    ! CSR round trip, exact: indices 1-based again, values bit for bit.
    call check_ok(silc_get_csr('Az', m2, n2, grp, gci, gv), 'get complex CSR')
    if (allocated(gv)) then
      call check(m2 == n .and. n2 == n .and. all(grp == rp) .and. all(gci == ci(1:k)) .and. &
                 all(gv == vals(1:k)), 'complex CSR round trip')
    else
      call check(.false., 'complex CSR round trip: nothing fetched')
    end if
    ! A real values array takes no complex value: the library's message, nothing half-read.
    call check_fails(silc_get_csr('Az', m2, n2, grp, gci, rvals), '''Az'' is complex', &
                     'get_csr of a complex value into real values')

    ! Dense, column-major as Fortran stores it; a signed zero and a subnormal survive.
    z = reshape([(cmplx(i, -2 * i, c_double_complex), i = 1, 6)], [2, 3])
    z(1, 1) = cmplx(-0.0_c_double, tiny(1.0_c_double) / 4, c_double_complex)
    call check_ok(silc_put('Z', z), 'put a complex matrix')
    call check_ok(silc_get('Z', zback), 'get a complex matrix')
    bits = transfer(real(zback), bits)
    bits_back = transfer(real(z), bits_back)
    call check(all(bits == bits_back), 'complex matrix round trip: real parts bit for bit')
    bits = transfer(aimag(zback), bits)
    bits_back = transfer(aimag(z), bits_back)
    call check(all(bits == bits_back), 'complex matrix round trip: imaginary parts bit for bit')
    call check_ok(silc_exec("Zt = Z.'; Zh = Z'"), 'transposes of a complex matrix')
    call check_ok(silc_get('Zt', zt), 'get Z.''')
    call check(all(zt == transpose(z)), 'Z.'' is the plain transpose, in column-major order')
    call check_ok(silc_get('Zh', zt), 'get Z''')
    call check(all(zt == conjg(transpose(z))), 'Z'' is the conjugate transpose')

    ! A real array refuses a complex value, untouched; a complex one takes a real value.
    rz = 7
    call check_fails(silc_get('Z', rz), '''Z'' is complex', 'a complex value into a real array')
    call check(all(rz == 7), 'the refused real array is unchanged')
    call check_ok(silc_exec('Zr = real(Z)'), 'real(Z)')
    call check_ok(silc_get('Zr', zback), 'a real value into a complex array')
    call check(all(zback == cmplx(real(z), 0.0_c_double, c_double_complex)), 'real value, imaginary parts 0')

    call check_ok(silc_put('zs', (1.0_c_double, 2.0_c_double)), 'put a complex scalar')
    call check_ok(silc_exec('w = zs * zs'), 'complex scalar arithmetic')
    w = 0
    call check_ok(silc_get('w', w), 'get a complex scalar')
    call check(w == (-3.0_c_double, 4.0_c_double), '(1 + 2i)^2 = -3 + 4i')
  end subroutine test_complex

  ! One process: rank 0 of 1, and a block of rows is the whole value.
  subroutine test_rows()
    real(c_double) :: v(3) = [1, 2, 3], x(2, 3)
    real(c_double), allocatable :: got(:), got2(:, :), vals(:)
    integer :: rank, nranks, first, i
    integer(c_int64_t) :: first64
    integer, allocatable :: rp(:), ci(:)
    integer :: m, n
    call check_ok(silc_rank(rank, nranks), 'silc_rank')
    call check(rank == 0 .and. nranks == 1, 'one process is rank 0 of 1')

    call check_ok(silc_put_rows('rv', 1, v), 'put_rows of a whole vector')
    call check_ok(silc_exec('rw = 2 * rv'), 'exec on rv')
    first = -1
    call check_ok(silc_get_rows('rw', first, got), 'get_rows into an unallocated array')
    call check(first == 1 .and. allocated(got), 'get_rows allocates, first row 1')
    if (allocated(got)) call check(size(got) == 3 .and. all(got == 2 * v), 'get_rows values')
    got = [9.0_c_double]
    call check_ok(silc_get_rows('rv', first, got), 'get_rows reallocates')
    call check(size(got) == 3 .and. all(got == v), 'reallocated get_rows values')
    first64 = -1
    call check_ok(silc_get_rows('rv', first64, got), 'get_rows with an int64 first_row')
    call check(first64 == 1, 'int64 first row 1')

    x = reshape([(real(i, c_double), i = 1, 6)], [2, 3])
    call check_ok(silc_put_rows('RX', 1_c_int64_t, x), 'put_rows of a dense 2x3 block')
    call check_ok(silc_get_rows('RX', first, got2), 'get_rows into a 2-D array')
    call check(first == 1 .and. all(shape(got2) == [2, 3]), 'shape of the 2-D block')
    if (all(shape(got2) == [2, 3])) call check(all(got2 == x), 'dense block round trip')
    call check_fails(silc_get_rows('RX', first, got), '3 columns', 'get_rows of a matrix into 1-D')

    ! The 3x3 CSR of test_csr as a block of rows.
    call check_ok(silc_put_rows('RA', 1, 3, 3, [1, 3, 6, 8], [1, 2, 1, 2, 3, 2, 3], &
                                [4.0_c_double, -1.0_c_double, -1.0_c_double, 4.0_c_double, &
                                 -1.0_c_double, -1.0_c_double, 4.0_c_double]), 'put_rows of a CSR block')
    call check_ok(silc_get_csr('RA', m, n, rp, ci, vals), 'get_csr of RA')
    call check(m == 3 .and. n == 3 .and. all(rp == [1, 3, 6, 8]) .and. all(ci == [1, 2, 1, 2, 3, 2, 3]), &
               'CSR block round trip')
    call check_ok(silc_put_rows('RA64', 1_c_int64_t, 1_c_int64_t, 2_c_int64_t, &
                                [1_c_int64_t, 2_c_int64_t], [2_c_int64_t], [5.0_c_double]), &
                  'put_rows of an int64 CSR block')
    call check_ok(silc_get_rows('RA64', first, got2), 'CSR into a 2-D block')
    call check(all(shape(got2) == [1, 2]), 'shape of the CSR block')
    if (all(shape(got2) == [1, 2])) call check(got2(1, 1) == 0 .and. got2(1, 2) == 5, 'CSR block values')

    ! Mistakes: 0-based rows, a block that is not the whole value, bad CSR.
    call check_fails(silc_put_rows('Zr', 0, v), 'numbered from 1', 'first_row 0')
    call check_fails(silc_put_rows('Zr', 2, v), 'whole value', 'first_row 2 on one process')
    call check_fails(silc_put_rows('Zr', 1, 2, 2, [0, 1, 2], [0, 1], v), '1-based', '0-based CSR block')
    call check_fails(silc_put_rows('Zr', 1, 2, 2, [0, 1, 2], [0, 1], v), 'silc_put_rows', &
                     'CSR block mistakes name silc_put_rows')
    call check_fails(silc_exec('z = Zr'), 'Zr', 'no failed put_rows left Zr behind')
    call check_fails(silc_get_rows('nosuchname', first, got), 'nosuchname', 'get_rows of an undefined name')
  end subroutine test_rows

  ! Complex row blocks on one process: the block is the whole value, as for
  ! real ones; values come back bit for bit (products by 1 + 1i of small
  ! integers are exact).
  subroutine test_rows_complex()
    complex(c_double_complex), parameter :: i1 = (0.0_c_double, 1.0_c_double)
    complex(c_double_complex) :: v(3), x(2, 3)
    complex(c_double_complex), allocatable :: got(:), got2(:, :)
    real(c_double), allocatable :: rgot(:)
    integer :: first, i
    integer(c_int64_t) :: first64
    v = [(cmplx(i, -i, c_double_complex), i = 1, 3)]
    call check_ok(silc_put_rows('zrv', 1, v), 'put_rows of a complex vector')
    call check_ok(silc_exec('zrw = (1 + 1i) * zrv'), 'exec on a complex block')
    first = -1
    call check_ok(silc_get_rows('zrw', first, got), 'get_rows of a complex vector')
    call check(first == 1 .and. allocated(got), 'complex get_rows allocates, first row 1')
    if (allocated(got)) call check(size(got) == 3 .and. all(got == (1 + i1) * v), 'complex get_rows values')
    first64 = -1
    call check_ok(silc_get_rows('zrv', first64, got), 'complex get_rows with an int64 first_row')
    call check(first64 == 1 .and. all(got == v), 'complex get_rows int64: first row 1, values')
    call check_fails(silc_get_rows('zrw', first, rgot), '''zrw'' is complex', &
                     'get_rows of a complex value into a real array')
    call check(.not. allocated(rgot), 'a refused get_rows allocates nothing')

    x = reshape([(cmplx(i, 2 * i, c_double_complex), i = 1, 6)], [2, 3])
    call check_ok(silc_put_rows('ZRX', 1_c_int64_t, x), 'put_rows of a complex 2x3 block')
    call check_ok(silc_get_rows('ZRX', first, got2), 'complex get_rows into a 2-D array')
    call check(all(shape(got2) == [2, 3]), 'shape of the complex 2-D block')
    if (all(shape(got2) == [2, 3])) call check(all(got2 == x), 'complex dense block round trip')
    call check_fails(silc_get_rows('ZRX', first, got), '3 columns', 'complex get_rows of a matrix into 1-D')

    ! A complex 2x3 CSR block: row 1 has columns 1 and 3, row 2 column 2.
    call check_ok(silc_put_rows('ZRA', 1, 2, 3, [1, 3, 4], [1, 3, 2], [v(1), v(2), i1]), &
                  'put_rows of a complex CSR block')
    call check_ok(silc_get_rows('ZRA', first, got2), 'complex CSR into a 2-D block')
    if (all(shape(got2) == [2, 3])) then
      call check(all(got2(1, :) == [v(1), (0.0_c_double, 0.0_c_double), v(2)]) .and. &
                 all(got2(2, :) == [(0.0_c_double, 0.0_c_double), i1, (0.0_c_double, 0.0_c_double)]), &
                 'complex CSR block values')
    else
      call check(.false., 'shape of the complex CSR block')
    end if
    call check_ok(silc_put_rows('ZRA64', 1_c_int64_t, 1_c_int64_t, 2_c_int64_t, [1_c_int64_t, 2_c_int64_t], &
                                [2_c_int64_t], [i1]), 'put_rows of an int64 complex CSR block')
    call check_ok(silc_get_rows('ZRA64', first64, got2), 'int64 complex CSR block back')
    if (all(shape(got2) == [1, 2])) call check(all(got2(1, :) == [(0.0_c_double, 0.0_c_double), i1]), &
                                               'int64 complex CSR block values')
    call check_fails(silc_put_rows('ZRA', 1, 2, 3, [1, 3, 4], [1, 4, 2], [v(1), v(2), i1]), 'outside 1..3', &
                     'a complex CSR block with a bad column')

    ! A complex array takes a real value's rows, imaginary parts 0.
    call check_ok(silc_put_rows('rrv', 1, [1.5_c_double, -2.0_c_double]), 'put_rows of a real vector')
    call check_ok(silc_get_rows('rrv', first, got), 'a real value''s rows into a complex array')
    call check(size(got) == 2 .and. all(got == [(1.5_c_double, 0.0_c_double), (-2.0_c_double, 0.0_c_double)]), &
               'real rows, imaginary parts 0')
  end subroutine test_rows_complex

  ! After silc_finalize the row calls fail with a message, not a crash.
  subroutine test_rows_closed()
    real(c_double), allocatable :: got(:)
    integer :: rank, nranks, first
    call check_fails(silc_rank(rank, nranks), 'silc_init', 'silc_rank without a context')
    call check_fails(silc_put_rows('v', 1, [1.0_c_double]), 'silc_init', 'put_rows without a context')
    call check_fails(silc_get_rows('v', first, got), 'silc_init', 'get_rows without a context')
  end subroutine test_rows_closed

  subroutine check_near(got, want, tol, what)
    real(c_double), intent(in) :: got, want, tol
    character(len=*), intent(in) :: what
    character(len=80) :: detail
    write (detail, '(a, es23.16, a, es23.16)') ' (got ', got, ', want ', want
    call check(abs(got - want) <= tol, what // trim(detail) // ')')
  end subroutine check_near

end program test_fortran
