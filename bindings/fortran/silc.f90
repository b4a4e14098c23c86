! silc.f90 -- the Fortran binding of SILC: module `silc`.
!
! A Fortran program deposits arrays under names, asks for computation as text
! and fetches results by name, exactly as a C program does through silc.h:
!
!     use silc
!     if (silc_init() /= 0) error stop silc_errmsg()
!     ierr = silc_put_csr('A', n, n, rowptr, colind, values)   ! 1-based CSR
!     ierr = silc_put('b', b)                                   ! vector, n x 1
!     ierr = silc_exec('x = A \ b')
!     ierr = silc_get('x', x)                                   ! x must be n long
!     ierr = silc_finalize()
!
! The module is pure ISO_C_BINDING over the public C API (the default-context
! calls SILC_INIT/PUT/GET/EXEC/FINALIZE and the envelope constructors), so it
! runs embedded or against a server (SILC_SERVER=tcp://host:port) unchanged.
!
! Every function returns an integer status, 0 on success; after a failure
! silc_errmsg() says why.  Arrays are real(c_double).  A 1-D array is a vector
! (n x 1), a 2-D array a dense matrix in Fortran's own column-major order (no
! transposition).  CSR indices are 1-based on the Fortran side and converted to
! the 0-based int64 arrays of the C API here.  silc_get never allocates or
! resizes the caller's array: it must already have the value's shape
! (silc_get_shape tells it); silc_get_csr allocates its allocatable outputs.
module silc
  use, intrinsic :: iso_c_binding
  implicit none
  private

  public :: silc_init, silc_finalize, silc_put, silc_get, silc_exec
  public :: silc_put_csr, silc_get_csr, silc_get_shape
  public :: silc_errmsg, silc_warnings

  ! silc_format_t of silc.h.
  enum, bind(c)
    enumerator :: SILC_DENSE = 0, SILC_CSR = 1, SILC_BAND = 2
  end enum

  ! Mirror of silc_envelope_t in silc.h, field for field (the enum is a C int,
  ! as gcc and clang lay it out without -fshort-enums): bind(c) gives it the
  ! C compiler's padding (8 bytes after `format` on LP64).  silc_init checks the
  ! mirror against the library before anything else uses it.
  type, bind(c) :: silc_envelope_t
    integer(c_int64_t) :: m, n
    integer(c_int) :: format
    type(c_ptr) :: values, rowptr, colind
    integer(c_int64_t) :: nnz, kl, ku
  end type silc_envelope_t

  interface silc_put
    module procedure put_scalar, put_vector, put_matrix
  end interface silc_put

  interface silc_get
    module procedure get_scalar, get_vector, get_matrix
  end interface silc_get

  interface silc_put_csr
    module procedure put_csr_int, put_csr_int64
  end interface silc_put_csr

  interface silc_get_csr
    module procedure get_csr_int, get_csr_int64
  end interface silc_get_csr

  ! The C API (core/include/silc.h) and strlen.
  interface
    integer(c_int) function c_silc_init() bind(c, name='SILC_INIT')
      import :: c_int
    end function c_silc_init

    integer(c_int) function c_silc_finalize() bind(c, name='SILC_FINALIZE')
      import :: c_int
    end function c_silc_finalize

    integer(c_int) function c_silc_put(name, e) bind(c, name='SILC_PUT')
      import :: c_int, c_char, silc_envelope_t
      character(kind=c_char), intent(in) :: name(*)
      type(silc_envelope_t), intent(in) :: e
    end function c_silc_put

    integer(c_int) function c_silc_get(e, name) bind(c, name='SILC_GET')
      import :: c_int, c_char, silc_envelope_t
      type(silc_envelope_t), intent(inout) :: e
      character(kind=c_char), intent(in) :: name(*)
    end function c_silc_get

    integer(c_int) function c_silc_exec(text) bind(c, name='SILC_EXEC')
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: text(*)
    end function c_silc_exec

    type(c_ptr) function c_silc_errmsg() bind(c, name='silc_errmsg')
      import :: c_ptr
    end function c_silc_errmsg

    type(c_ptr) function c_silc_warnings() bind(c, name='silc_warnings')
      import :: c_ptr
    end function c_silc_warnings

    integer(c_int) function c_envelope_dense(e, m, n, x) bind(c, name='silc_envelope_dense')
      import :: c_int, c_int64_t, c_double, silc_envelope_t
      type(silc_envelope_t), intent(inout) :: e
      integer(c_int64_t), value :: m, n
      real(c_double), intent(in) :: x(*)
    end function c_envelope_dense

    integer(c_int) function c_envelope_scalar(e, x) bind(c, name='silc_envelope_scalar')
      import :: c_int, c_double, silc_envelope_t
      type(silc_envelope_t), intent(inout) :: e
      real(c_double), value :: x
    end function c_envelope_scalar

    integer(c_int) function c_envelope_csr(e, m, n, rowptr, colind, values) &
        bind(c, name='silc_envelope_csr')
      import :: c_int, c_int64_t, c_double, silc_envelope_t
      type(silc_envelope_t), intent(inout) :: e
      integer(c_int64_t), value :: m, n
      integer(c_int64_t), intent(in) :: rowptr(*), colind(*)
      real(c_double), intent(in) :: values(*)
    end function c_envelope_csr

    integer(c_int) function c_envelope_band(e, m, n, kl, ku, band) bind(c, name='silc_envelope_band')
      import :: c_int, c_int64_t, c_double, silc_envelope_t
      type(silc_envelope_t), intent(inout) :: e
      integer(c_int64_t), value :: m, n, kl, ku
      real(c_double), intent(in) :: band(*)
    end function c_envelope_band

    integer(c_int64_t) function c_envelope_rows(e) bind(c, name='silc_envelope_rows')
      import :: c_int64_t, silc_envelope_t
      type(silc_envelope_t), intent(in) :: e
    end function c_envelope_rows

    integer(c_int64_t) function c_envelope_cols(e) bind(c, name='silc_envelope_cols')
      import :: c_int64_t, silc_envelope_t
      type(silc_envelope_t), intent(in) :: e
    end function c_envelope_cols

    integer(c_int) function c_envelope_to_dense(e, x) bind(c, name='silc_envelope_to_dense')
      import :: c_int, c_double, silc_envelope_t
      type(silc_envelope_t), intent(in) :: e
      real(c_double), intent(inout) :: x(*)
    end function c_envelope_to_dense

    subroutine c_envelope_free(e) bind(c, name='silc_envelope_free')
      import :: silc_envelope_t
      type(silc_envelope_t), intent(inout) :: e
    end subroutine c_envelope_free

    integer(c_size_t) function c_strlen(s) bind(c, name='strlen')
      import :: c_size_t, c_ptr
      type(c_ptr), value :: s
    end function c_strlen
  end interface

  ! Failures detected here (wrong array size, bad 1-based indices) never reach
  ! the library, so their message is kept here; `own_failure` says whether the
  ! last failure was ours or the library's.  Each public call clears it.
  character(len=:), allocatable :: own_msg
  logical :: own_failure = .false.
  logical :: layout_checked = .false.

contains

  ! ---- context ---------------------------------------------------------------

  !> Opens the default context: embedded, or remote when SILC_SERVER is set.
  integer function silc_init() result(status)
    own_failure = .false.
    if (.not. layout_checked) then
      status = check_layout()
      if (status /= 0) return
      layout_checked = .true.
    end if
    status = int(c_silc_init())
  end function silc_init

  !> Closes the default context; every name deposited is gone afterwards.
  integer function silc_finalize() result(status)
    own_failure = .false.
    status = int(c_silc_finalize())
  end function silc_finalize

  !> Runs statements of the SILC language, e.g. 'b = B * u; u = A \ b'.
  integer function silc_exec(text) result(status)
    character(len=*), intent(in) :: text
    own_failure = .false.
    status = int(c_silc_exec(c_string(text)))
  end function silc_exec

  !> Message of the last failure (kept until the next failure replaces it).
  function silc_errmsg() result(msg)
    character(len=:), allocatable :: msg
    if (own_failure) then
      msg = own_msg
    else
      msg = f_string(c_silc_errmsg())
    end if
  end function silc_errmsg

  !> Warnings of the last silc_exec, one per line ('' if none): results that
  !> were computed but deserve distrust, e.g. a nearly singular solve.
  function silc_warnings() result(msg)
    character(len=:), allocatable :: msg
    msg = f_string(c_silc_warnings())
  end function silc_warnings

  ! ---- put -------------------------------------------------------------------

  integer function put_scalar(name, x) result(status)
    character(len=*), intent(in) :: name
    real(c_double), intent(in) :: x
    type(silc_envelope_t) :: e
    own_failure = .false.
    e = empty_envelope()
    status = int(c_envelope_scalar(e, x))
    if (status == 0) status = put_envelope(name, e)
  end function put_scalar

  integer function put_vector(name, x) result(status)
    character(len=*), intent(in) :: name
    real(c_double), intent(in) :: x(:)
    own_failure = .false.
    status = put_dense(name, int(size(x), c_int64_t), 1_c_int64_t, x)
  end function put_vector

  integer function put_matrix(name, x) result(status)
    character(len=*), intent(in) :: name
    real(c_double), intent(in) :: x(:, :)
    own_failure = .false.
    status = put_dense(name, int(size(x, 1), c_int64_t), int(size(x, 2), c_int64_t), x)
  end function put_matrix

  !> Deposits an m x n sparse matrix given as 1-based CSR: row i holds
  !> values(rowptr(i):rowptr(i+1)-1) in columns colind(rowptr(i):rowptr(i+1)-1).
  integer function put_csr_int(name, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer, intent(in) :: m, n, rowptr(:), colind(:)
    real(c_double), intent(in) :: values(:)
    integer(c_int64_t), allocatable :: rp(:), ci(:)
    own_failure = .false.
    allocate(rp(size(rowptr)), ci(size(colind)))
    rp(:) = int(rowptr, c_int64_t)
    ci(:) = int(colind, c_int64_t)
    status = put_csr_0based(name, int(m, c_int64_t), int(n, c_int64_t), rp, ci, values)
  end function put_csr_int

  integer function put_csr_int64(name, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: m, n, rowptr(:), colind(:)
    real(c_double), intent(in) :: values(:)
    integer(c_int64_t), allocatable :: rp(:), ci(:)
    own_failure = .false.
    allocate(rp(size(rowptr)), ci(size(colind)))
    rp(:) = rowptr
    ci(:) = colind
    status = put_csr_0based(name, m, n, rp, ci, values)
  end function put_csr_int64

  ! ---- get -------------------------------------------------------------------

  !> Shape of the value bound to name, to allocate before silc_get.
  integer function silc_get_shape(name, m, n) result(status)
    character(len=*), intent(in) :: name
    integer, intent(out) :: m, n
    type(silc_envelope_t) :: e
    own_failure = .false.
    m = 0
    n = 0
    status = get_envelope(name, e)
    if (status /= 0) return
    if (e%m > huge(m) .or. e%n > huge(n)) then
      status = fail('silc_get_shape: ''' // trim(name) // ''' is ' // shape_text(e%m, e%n) // &
                    ', too large for default integers')
    else
      m = int(e%m)
      n = int(e%n)
    end if
    call c_envelope_free(e)
  end function silc_get_shape

  integer function get_scalar(name, x) result(status)
    character(len=*), intent(in) :: name
    real(c_double), intent(inout) :: x
    real(c_double) :: buf(1)
    own_failure = .false.
    status = get_dense(name, 1_c_int64_t, 1_c_int64_t, .false., 'a scalar', buf)
    if (status == 0) x = buf(1)
  end function get_scalar

  !> A 1-D array takes either orientation (n x 1 or 1 x n): it has none itself.
  integer function get_vector(name, x) result(status)
    character(len=*), intent(in) :: name
    real(c_double), intent(inout) :: x(:)
    own_failure = .false.
    status = get_dense(name, int(size(x), c_int64_t), 1_c_int64_t, .true., &
                       'an array of size ' // int_text(int(size(x), c_int64_t)), x)
  end function get_vector

  integer function get_matrix(name, x) result(status)
    character(len=*), intent(in) :: name
    real(c_double), intent(inout) :: x(:, :)
    integer(c_int64_t) :: m, n
    own_failure = .false.
    m = int(size(x, 1), c_int64_t)
    n = int(size(x, 2), c_int64_t)
    status = get_dense(name, m, n, .false., 'an array of shape ' // shape_text(m, n), x)
  end function get_matrix

  !> Fetches a sparse matrix as 1-based CSR into allocatable arrays (allocated,
  !> or reallocated, here).  Dense and band values are refused: fetch those
  !> into a 2-D array with silc_get.
  integer function get_csr_int(name, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer, intent(out) :: m, n
    integer, allocatable, intent(inout) :: rowptr(:), colind(:)
    real(c_double), allocatable, intent(inout) :: values(:)
    type(silc_envelope_t) :: e
    integer(c_int64_t), pointer :: rp(:), ci(:)
    own_failure = .false.
    m = 0
    n = 0
    status = get_csr_envelope(name, e, rp, ci, values)
    if (status /= 0) return
    if (max(e%m, e%n, e%nnz + 1) > huge(m)) then
      status = fail('silc_get_csr: ''' // trim(name) // ''' (' // shape_text(e%m, e%n) // &
                    ' with ' // int_text(e%nnz) // ' entries) needs integer(c_int64_t) arrays')
    else
      m = int(e%m)
      n = int(e%n)
      call replace_int(rowptr, int(rp + 1))
      call replace_int(colind, int(ci + 1))
    end if
    call c_envelope_free(e)
  end function get_csr_int

  integer function get_csr_int64(name, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(out) :: m, n
    integer(c_int64_t), allocatable, intent(inout) :: rowptr(:), colind(:)
    real(c_double), allocatable, intent(inout) :: values(:)
    type(silc_envelope_t) :: e
    integer(c_int64_t), pointer :: rp(:), ci(:)
    own_failure = .false.
    m = 0
    n = 0
    status = get_csr_envelope(name, e, rp, ci, values)
    if (status /= 0) return
    m = e%m
    n = e%n
    if (allocated(rowptr)) deallocate(rowptr)
    if (allocated(colind)) deallocate(colind)
    rowptr = rp + 1
    colind = ci + 1
    call c_envelope_free(e)
  end function get_csr_int64

  ! ---- helpers ---------------------------------------------------------------

  integer function put_dense(name, m, n, x) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: m, n
    real(c_double), intent(in) :: x(*)
    type(silc_envelope_t) :: e
    e = empty_envelope()
    status = int(c_envelope_dense(e, m, n, x))
    if (status == 0) status = put_envelope(name, e)
  end function put_dense

  ! Deposits e and frees it whatever happens.
  integer function put_envelope(name, e) result(status)
    character(len=*), intent(in) :: name
    type(silc_envelope_t), intent(inout) :: e
    status = int(c_silc_put(c_string(name), e))
    call c_envelope_free(e)
  end function put_envelope

  ! Checks 1-based CSR, so a mistake is reported in the caller's own indices,
  ! then shifts rp and ci to 0-based in place and deposits.
  integer function put_csr_0based(name, m, n, rp, ci, values) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: m, n
    integer(c_int64_t), intent(inout) :: rp(:), ci(:)
    real(c_double), intent(in) :: values(:)
    character(len=*), parameter :: who = 'silc_put_csr: '
    type(silc_envelope_t) :: e
    integer(c_int64_t) :: i, k, nnz
    integer(c_int64_t), allocatable :: seen(:)

    if (m < 0 .or. n < 0) then
      status = fail(who // 'invalid size ' // shape_text(m, n))
      return
    end if
    if (size(rp, kind=c_int64_t) < m + 1) then
      status = fail(who // 'rowptr has ' // int_text(size(rp, kind=c_int64_t)) // &
                    ' entries, a ' // shape_text(m, n) // ' matrix needs m+1 = ' // int_text(m + 1))
      return
    end if
    if (rp(1) /= 1) then
      status = fail(who // 'rowptr(1) is ' // int_text(rp(1)) // ' but must be 1: ' // &
                    'Fortran CSR indices are 1-based')
      return
    end if
    do i = 1, m
      if (rp(i + 1) < rp(i)) then
        status = fail(who // 'rowptr decreases at row ' // int_text(i) // ': rowptr(' // &
                      int_text(i) // ') = ' // int_text(rp(i)) // ', rowptr(' // &
                      int_text(i + 1) // ') = ' // int_text(rp(i + 1)))
        return
      end if
    end do
    nnz = rp(m + 1) - 1
    if (size(ci, kind=c_int64_t) < nnz .or. size(values, kind=c_int64_t) < nnz) then
      status = fail(who // 'rowptr(m+1) - 1 = ' // int_text(nnz) // ' entries but colind has ' // &
                    int_text(size(ci, kind=c_int64_t)) // ' and values ' // &
                    int_text(size(values, kind=c_int64_t)))
      return
    end if
    ! seen(j) is the last row that used column j: duplicates found in O(nnz).
    allocate(seen(n))
    seen(:) = 0
    do i = 1, m
      do k = rp(i), rp(i + 1) - 1
        if (ci(k) < 1 .or. ci(k) > n) then
          status = fail(who // 'colind(' // int_text(k) // ') = ' // int_text(ci(k)) // &
                        ' is outside 1..' // int_text(n) // ' (indices are 1-based)')
          return
        end if
        if (seen(ci(k)) == i) then
          status = fail(who // 'row ' // int_text(i) // ' has column ' // int_text(ci(k)) // &
                        ' twice (colind(' // int_text(k) // ')); use sparse(i, j, v, m, n) ' // &
                        'in the language to sum duplicates')
          return
        end if
        seen(ci(k)) = i
      end do
    end do

    rp = rp - 1
    ci = ci - 1
    e = empty_envelope()
    ! colind/values may be empty: the C side reads nnz = rp(m+1) entries, none.
    status = int(c_envelope_csr(e, m, n, rp, ci, values))
    if (status == 0) status = put_envelope(name, e)
  end function put_csr_0based

  integer function get_envelope(name, e) result(status)
    character(len=*), intent(in) :: name
    type(silc_envelope_t), intent(out) :: e
    e = empty_envelope()
    status = int(c_silc_get(e, c_string(name)))
  end function get_envelope

  ! Fetches name into x(1:m*n) if its shape is m x n (or n x m for a vector,
  ! when either_way); otherwise fails naming both shapes.
  integer function get_dense(name, m, n, either_way, what, x) result(status)
    character(len=*), intent(in) :: name, what
    integer(c_int64_t), intent(in) :: m, n
    logical, intent(in) :: either_way
    real(c_double), intent(inout) :: x(*)
    type(silc_envelope_t) :: e
    logical :: fits
    status = get_envelope(name, e)
    if (status /= 0) return
    fits = e%m == m .and. e%n == n
    if (either_way) fits = fits .or. (min(e%m, e%n) <= 1 .and. e%m * e%n == m * n)
    if (fits) then
      status = int(c_envelope_to_dense(e, x))
    else
      status = fail('silc_get: ''' // trim(name) // ''' is ' // &
                    shape_text(c_envelope_rows(e), c_envelope_cols(e)) // ' but was asked into ' // &
                    what // '; allocate it after silc_get_shape(name, m, n)')
    end if
    call c_envelope_free(e)
  end function get_dense

  ! Fetches a CSR value; rp and ci point into e (0-based) until it is freed,
  ! values is already copied out.
  integer function get_csr_envelope(name, e, rp, ci, values) result(status)
    character(len=*), intent(in) :: name
    type(silc_envelope_t), intent(out) :: e
    integer(c_int64_t), pointer, intent(out) :: rp(:), ci(:)
    real(c_double), allocatable, intent(inout) :: values(:)
    real(c_double), pointer :: v(:)
    nullify(rp, ci)
    status = get_envelope(name, e)
    if (status /= 0) return
    if (e%format /= SILC_CSR) then
      status = fail('silc_get_csr: ''' // trim(name) // ''' is a ' // shape_text(e%m, e%n) // ' ' // &
                    trim(merge('dense', 'band ', e%format == SILC_DENSE)) // &
                    ' matrix, not sparse; fetch it into a 2-D array with silc_get')
      call c_envelope_free(e)
      return
    end if
    call c_f_pointer(e%rowptr, rp, [e%m + 1])
    call c_f_pointer(e%colind, ci, [e%nnz])
    call c_f_pointer(e%values, v, [e%nnz])
    if (allocated(values)) deallocate(values)
    values = v
  end function get_csr_envelope

  subroutine replace_int(a, b)
    integer, allocatable, intent(inout) :: a(:)
    integer, intent(in) :: b(:)
    if (allocated(a)) deallocate(a)
    a = b
  end subroutine replace_int

  ! The library and this module must agree on silc_envelope_t, or every call
  ! would read garbage: build a CSR and a band envelope in C and read each
  ! field back through the mirror.
  integer function check_layout() result(status)
    type(silc_envelope_t) :: csr, band
    integer(c_int64_t) :: rows, cols
    integer(c_int64_t), parameter :: rp(3) = [0_c_int64_t, 1_c_int64_t, 2_c_int64_t]
    integer(c_int64_t), parameter :: ci(2) = [0_c_int64_t, 2_c_int64_t]
    real(c_double), parameter :: v(12) = 0.0_c_double
    logical :: ok
    csr = empty_envelope()
    band = empty_envelope()
    status = int(c_envelope_csr(csr, 2_c_int64_t, 3_c_int64_t, rp, ci, v))
    if (status /= 0) return
    status = int(c_envelope_band(band, 4_c_int64_t, 3_c_int64_t, 1_c_int64_t, 2_c_int64_t, v))
    if (status == 0) then
      rows = c_envelope_rows(csr)
      cols = c_envelope_cols(csr)
      ok = csr%m == 2 .and. csr%n == 3 .and. csr%format == SILC_CSR .and. csr%nnz == 2 &
           .and. c_associated(csr%values) .and. c_associated(csr%rowptr) &
           .and. c_associated(csr%colind) .and. rows == 2 .and. cols == 3 &
           .and. band%m == 4 .and. band%n == 3 .and. band%format == SILC_BAND &
           .and. band%kl == 1 .and. band%ku == 2 .and. band%nnz == 12
      if (.not. ok) status = fail('silc_init: the Fortran mirror of silc_envelope_t does not ' // &
                                  'match the library''s silc.h; rebuild the silc module ' // &
                                  'against this libsilc')
    end if
    call c_envelope_free(csr)
    call c_envelope_free(band)
  end function check_layout

  pure function empty_envelope() result(e)
    type(silc_envelope_t) :: e
    e = silc_envelope_t(0_c_int64_t, 0_c_int64_t, SILC_DENSE, c_null_ptr, c_null_ptr, c_null_ptr, &
                        0_c_int64_t, 0_c_int64_t, 0_c_int64_t)
  end function empty_envelope

  integer function fail(msg) result(status)
    character(len=*), intent(in) :: msg
    own_msg = msg
    own_failure = .true.
    status = 1
  end function fail

  ! NUL-terminated copy for C; trailing blanks of fixed-length variables dropped.
  pure function c_string(s) result(cs)
    character(len=*), intent(in) :: s
    character(kind=c_char, len=:), allocatable :: cs
    cs = trim(s) // c_null_char
  end function c_string

  ! Copy of a C string owned by the library.
  function f_string(p) result(s)
    type(c_ptr), intent(in) :: p
    character(len=:), allocatable :: s
    character(kind=c_char), pointer :: chars(:)
    integer :: i, n
    if (.not. c_associated(p)) then
      s = ''
      return
    end if
    n = int(c_strlen(p))
    call c_f_pointer(p, chars, [n])
    allocate(character(len=n) :: s)
    do i = 1, n
      s(i:i) = chars(i)
    end do
  end function f_string

  pure function int_text(i) result(s)
    integer(c_int64_t), intent(in) :: i
    character(len=:), allocatable :: s
    character(len=24) :: buf
    write (buf, '(i0)') i
    s = trim(buf)
  end function int_text

  pure function shape_text(m, n) result(s)
    integer(c_int64_t), intent(in) :: m, n
    character(len=:), allocatable :: s
    s = int_text(m) // 'x' // int_text(n)
  end function shape_text

end module silc
