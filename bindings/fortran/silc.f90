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
! calls SILC_INIT/PUT/GET/EXEC/FINALIZE, the row-block calls silc_put_rows/
! silc_get_rows/silc_context_rank on silc_default_context(), and the envelope
! constructors), so it runs embedded or against a server
! (SILC_SERVER=tcp://host:port) unchanged.
!
! MPI programs (SPMD, silc.h "MPI programs"): link libsilc_mpi as well
! (CMake: target_link_libraries(prog PRIVATE silc_fortran silc_mpi)), call
! MPI_Init, and run with SILC_MODE=spmd: silc_init() then opens the default
! context over MPI_COMM_WORLD, one engine per rank (there is no silc_init_mpi
! taking a communicator: SILC_MODE=spmd is the way).  Every call is then
! collective -- all ranks make the same calls in the same order -- and each
! rank deposits and fetches only its own rows:
!
!     call MPI_Init(ierr)
!     if (silc_init() /= 0) error stop silc_errmsg()           ! SILC_MODE=spmd
!     ierr = silc_rank(rank, nranks)                         ! 0-based, as MPI
!     ierr = silc_put_rows('A', first, m, n, rowptr, colind, values)  ! my m rows
!     ierr = silc_put_rows('b', first, b)                    ! b(1:m): my rows
!     ierr = silc_exec('x = A \ b')
!     ierr = silc_get_rows('x', first, x)                    ! allocates x(1:m)
!     ierr = silc_finalize()
!     call MPI_Finalize(ierr)
!
! Row numbers are 1-based here (first = 1 on the rank holding the first row;
! the C API's are 0-based and converted).  The blocks of the ranks, in rank
! order, must tile the rows with no gap or overlap; a CSR block has the
! value's global column count n, local rowptr (rowptr(1) = 1) and global
! 1-based column indices.  values, b and x may be complex(c_double_complex)
! as for silc_put / silc_get: a complex x takes a complex value's rows
! (silc_get_rows_complex in C), a real x refuses them.  On one process
! (embedded, remote, or SPMD under mpirun -np 1) the block is the whole
! value, first = 1, so the same program runs without MPI too.  A failure found here before the collective call
! (e.g. first < 1) still makes that call, so the other ranks fail with it
! instead of waiting.
!
! Every function returns an integer status, 0 on success; after a failure
! silc_errmsg() says why.  Arrays are real(c_double), or complex(c_double_complex)
! (complex(8)) for complex values: the same generic calls take either, a
! complex array is stored as a complex value (Fortran's complex layout, real
! and imaginary part side by side, is SILC's own), and a complex array
! fetches a complex value or a real one (imaginary parts 0), while a real
! array refuses a complex value with the library's message ("'z' is
! complex ..."), never taking half of it.  A 1-D array is a vector
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
  public :: silc_put_rows, silc_get_rows, silc_rank

  ! silc_format_t of silc.h.
  enum, bind(c)
    enumerator :: SILC_DENSE = 0, SILC_CSR = 1, SILC_BAND = 2, SILC_COMPLEX = 16
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

  ! Each generic takes real(c_double) or complex(c_double_complex) values.
  interface silc_put
    module procedure put_scalar, put_vector, put_matrix
    module procedure put_scalar_complex, put_vector_complex, put_matrix_complex
  end interface silc_put

  interface silc_get
    module procedure get_scalar, get_vector, get_matrix
    module procedure get_scalar_complex, get_vector_complex, get_matrix_complex
  end interface silc_get

  interface silc_put_csr
    module procedure put_csr_int, put_csr_int64, put_csr_int_complex, put_csr_int64_complex
  end interface silc_put_csr

  interface silc_get_csr
    module procedure get_csr_int, get_csr_int64, get_csr_int_complex, get_csr_int64_complex
  end interface silc_get_csr

  ! silc_put_rows(name, first_row, x) for a dense block (1-D or 2-D), and
  ! silc_put_rows(name, first_row, m, n, rowptr, colind, values) for a CSR
  ! block; first_row is 1-based, default integer or integer(c_int64_t) (for
  ! CSR of the kind of the other integers).  x and values are real(c_double)
  ! or complex(c_double_complex), as for silc_put.
  interface silc_put_rows
    module procedure put_rows_vector, put_rows_vector_int64, put_rows_matrix, put_rows_matrix_int64
    module procedure put_rows_csr_int, put_rows_csr_int64
    module procedure put_rows_vector_complex, put_rows_vector_int64_complex
    module procedure put_rows_matrix_complex, put_rows_matrix_int64_complex
    module procedure put_rows_csr_int_complex, put_rows_csr_int64_complex
  end interface silc_put_rows

  ! silc_get_rows(name, first_row, x): this rank's rows into an allocatable
  ! 1-D or 2-D array, first_row (1-based, intent(out)) the first of them.  A
  ! complex array takes a complex value's rows (or a real one's, imaginary
  ! parts 0); a real array refuses a complex value, as silc_get does.
  interface silc_get_rows
    module procedure get_rows_vector, get_rows_vector_int64, get_rows_matrix, get_rows_matrix_int64
    module procedure get_rows_vector_complex, get_rows_vector_int64_complex
    module procedure get_rows_matrix_complex, get_rows_matrix_int64_complex
  end interface silc_get_rows

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

    integer(c_int) function c_silc_get_complex(ctx, e, name) bind(c, name='silc_get_complex')
      import :: c_int, c_char, c_ptr, silc_envelope_t
      type(c_ptr), value :: ctx
      type(silc_envelope_t), intent(inout) :: e
      character(kind=c_char), intent(in) :: name(*)
    end function c_silc_get_complex

    type(c_ptr) function c_silc_default_context() bind(c, name='silc_default_context')
      import :: c_ptr
    end function c_silc_default_context

    integer(c_int) function c_silc_put_rows(ctx, name, first_row, e) bind(c, name='silc_put_rows')
      import :: c_int, c_int64_t, c_char, c_ptr, silc_envelope_t
      type(c_ptr), value :: ctx
      character(kind=c_char), intent(in) :: name(*)
      integer(c_int64_t), value :: first_row
      type(silc_envelope_t), intent(in) :: e
    end function c_silc_put_rows

    integer(c_int) function c_silc_get_rows(ctx, e, first_row, name) bind(c, name='silc_get_rows')
      import :: c_int, c_int64_t, c_char, c_ptr, silc_envelope_t
      type(c_ptr), value :: ctx
      type(silc_envelope_t), intent(inout) :: e
      integer(c_int64_t), intent(out) :: first_row
      character(kind=c_char), intent(in) :: name(*)
    end function c_silc_get_rows

    integer(c_int) function c_silc_get_rows_complex(ctx, e, first_row, name) bind(c, name='silc_get_rows_complex')
      import :: c_int, c_int64_t, c_char, c_ptr, silc_envelope_t
      type(c_ptr), value :: ctx
      type(silc_envelope_t), intent(inout) :: e
      integer(c_int64_t), intent(out) :: first_row
      character(kind=c_char), intent(in) :: name(*)
    end function c_silc_get_rows_complex

    integer(c_int) function c_silc_context_rank(ctx, rank, size) bind(c, name='silc_context_rank')
      import :: c_int, c_ptr
      type(c_ptr), value :: ctx
      integer(c_int), intent(out) :: rank, size
    end function c_silc_context_rank

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

    integer(c_int) function c_envelope_dense_complex(e, m, n, x) bind(c, name='silc_envelope_dense_complex')
      import :: c_int, c_int64_t, c_double_complex, silc_envelope_t
      type(silc_envelope_t), intent(inout) :: e
      integer(c_int64_t), value :: m, n
      complex(c_double_complex), intent(in) :: x(*)
    end function c_envelope_dense_complex

    integer(c_int) function c_envelope_csr_complex(e, m, n, rowptr, colind, values) &
        bind(c, name='silc_envelope_csr_complex')
      import :: c_int, c_int64_t, c_double_complex, silc_envelope_t
      type(silc_envelope_t), intent(inout) :: e
      integer(c_int64_t), value :: m, n
      integer(c_int64_t), intent(in) :: rowptr(*), colind(*)
      complex(c_double_complex), intent(in) :: values(*)
    end function c_envelope_csr_complex

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

  integer function put_scalar_complex(name, x) result(status)
    character(len=*), intent(in) :: name
    complex(c_double_complex), intent(in) :: x
    own_failure = .false.
    status = put_dense_complex(name, 1_c_int64_t, 1_c_int64_t, [x])
  end function put_scalar_complex

  integer function put_vector_complex(name, x) result(status)
    character(len=*), intent(in) :: name
    complex(c_double_complex), intent(in) :: x(:)
    own_failure = .false.
    status = put_dense_complex(name, int(size(x), c_int64_t), 1_c_int64_t, x)
  end function put_vector_complex

  integer function put_matrix_complex(name, x) result(status)
    character(len=*), intent(in) :: name
    complex(c_double_complex), intent(in) :: x(:, :)
    own_failure = .false.
    status = put_dense_complex(name, int(size(x, 1), c_int64_t), int(size(x, 2), c_int64_t), x)
  end function put_matrix_complex

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
    status = put_csr_0based(name, int(m, c_int64_t), int(n, c_int64_t), rp, ci, values=values)
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
    status = put_csr_0based(name, m, n, rp, ci, values=values)
  end function put_csr_int64

  !> A complex m x n sparse matrix as 1-based CSR, as silc_put_csr above.
  integer function put_csr_int_complex(name, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer, intent(in) :: m, n, rowptr(:), colind(:)
    complex(c_double_complex), intent(in) :: values(:)
    integer(c_int64_t), allocatable :: rp(:), ci(:)
    own_failure = .false.
    allocate(rp(size(rowptr)), ci(size(colind)))
    rp(:) = int(rowptr, c_int64_t)
    ci(:) = int(colind, c_int64_t)
    status = put_csr_0based(name, int(m, c_int64_t), int(n, c_int64_t), rp, ci, zvalues=values)
  end function put_csr_int_complex

  integer function put_csr_int64_complex(name, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: m, n, rowptr(:), colind(:)
    complex(c_double_complex), intent(in) :: values(:)
    integer(c_int64_t), allocatable :: rp(:), ci(:)
    own_failure = .false.
    allocate(rp(size(rowptr)), ci(size(colind)))
    rp(:) = rowptr
    ci(:) = colind
    status = put_csr_0based(name, m, n, rp, ci, zvalues=values)
  end function put_csr_int64_complex

  ! ---- get -------------------------------------------------------------------

  !> Shape of the value bound to name, to allocate before silc_get.
  integer function silc_get_shape(name, m, n) result(status)
    character(len=*), intent(in) :: name
    integer, intent(out) :: m, n
    type(silc_envelope_t) :: e
    own_failure = .false.
    m = 0
    n = 0
    status = get_envelope(name, e, accept_complex=.true.)
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

  integer function get_scalar_complex(name, x) result(status)
    character(len=*), intent(in) :: name
    complex(c_double_complex), intent(inout) :: x
    complex(c_double_complex) :: buf(1)
    own_failure = .false.
    status = get_dense_complex(name, 1_c_int64_t, 1_c_int64_t, .false., 'a scalar', buf)
    if (status == 0) x = buf(1)
  end function get_scalar_complex

  integer function get_vector_complex(name, x) result(status)
    character(len=*), intent(in) :: name
    complex(c_double_complex), intent(inout) :: x(:)
    own_failure = .false.
    status = get_dense_complex(name, int(size(x), c_int64_t), 1_c_int64_t, .true., &
                               'an array of size ' // int_text(int(size(x), c_int64_t)), x)
  end function get_vector_complex

  integer function get_matrix_complex(name, x) result(status)
    character(len=*), intent(in) :: name
    complex(c_double_complex), intent(inout) :: x(:, :)
    integer(c_int64_t) :: m, n
    own_failure = .false.
    m = int(size(x, 1), c_int64_t)
    n = int(size(x, 2), c_int64_t)
    status = get_dense_complex(name, m, n, .false., 'an array of shape ' // shape_text(m, n), x)
  end function get_matrix_complex

  !> Fetches a sparse matrix as 1-based CSR into allocatable arrays (allocated,
  !> or reallocated, here).  Dense and band values are refused: fetch those
  !> into a 2-D array with silc_get.  Complex values arrays take a complex
  !> matrix (or a real one, imaginary parts 0); real ones refuse a complex one.
  integer function get_csr_int(name, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer, intent(out) :: m, n
    integer, allocatable, intent(inout) :: rowptr(:), colind(:)
    real(c_double), allocatable, intent(inout) :: values(:)
    status = get_csr_default_int(name, m, n, rowptr, colind, values=values)
  end function get_csr_int

  integer function get_csr_int_complex(name, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer, intent(out) :: m, n
    integer, allocatable, intent(inout) :: rowptr(:), colind(:)
    complex(c_double_complex), allocatable, intent(inout) :: values(:)
    status = get_csr_default_int(name, m, n, rowptr, colind, zvalues=values)
  end function get_csr_int_complex

  integer function get_csr_int64(name, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(out) :: m, n
    integer(c_int64_t), allocatable, intent(inout) :: rowptr(:), colind(:)
    real(c_double), allocatable, intent(inout) :: values(:)
    status = get_csr_c_int64(name, m, n, rowptr, colind, values=values)
  end function get_csr_int64

  integer function get_csr_int64_complex(name, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(out) :: m, n
    integer(c_int64_t), allocatable, intent(inout) :: rowptr(:), colind(:)
    complex(c_double_complex), allocatable, intent(inout) :: values(:)
    status = get_csr_c_int64(name, m, n, rowptr, colind, zvalues=values)
  end function get_csr_int64_complex

  ! silc_get_csr with default-integer indices; values (real) or zvalues
  ! (complex), one of them present.
  integer function get_csr_default_int(name, m, n, rowptr, colind, values, zvalues) result(status)
    character(len=*), intent(in) :: name
    integer, intent(out) :: m, n
    integer, allocatable, intent(inout) :: rowptr(:), colind(:)
    real(c_double), allocatable, intent(inout), optional :: values(:)
    complex(c_double_complex), allocatable, intent(inout), optional :: zvalues(:)
    type(silc_envelope_t) :: e
    integer(c_int64_t), pointer :: rp(:), ci(:)
    own_failure = .false.
    m = 0
    n = 0
    status = get_csr_envelope(name, e, rp, ci, values, zvalues)
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
  end function get_csr_default_int

  ! silc_get_csr with integer(c_int64_t) indices, as get_csr_default_int.
  integer function get_csr_c_int64(name, m, n, rowptr, colind, values, zvalues) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(out) :: m, n
    integer(c_int64_t), allocatable, intent(inout) :: rowptr(:), colind(:)
    real(c_double), allocatable, intent(inout), optional :: values(:)
    complex(c_double_complex), allocatable, intent(inout), optional :: zvalues(:)
    type(silc_envelope_t) :: e
    integer(c_int64_t), pointer :: rp(:), ci(:)
    own_failure = .false.
    m = 0
    n = 0
    status = get_csr_envelope(name, e, rp, ci, values, zvalues)
    if (status /= 0) return
    m = e%m
    n = e%n
    if (allocated(rowptr)) deallocate(rowptr)
    if (allocated(colind)) deallocate(colind)
    rowptr = rp + 1
    colind = ci + 1
    call c_envelope_free(e)
  end function get_csr_c_int64

  ! ---- rows (MPI programs, SPMD) ----------------------------------------------

  !> This process's rank (0-based, as MPI numbers ranks) and the number of
  !> ranks of the default context: 0 and 1 unless it is an SPMD one.
  integer function silc_rank(rank, size) result(status)
    integer, intent(out) :: rank, size
    type(c_ptr) :: ctx
    integer(c_int) :: r, p
    own_failure = .false.
    rank = 0
    size = 1
    status = default_context('silc_rank: ', ctx)
    if (status /= 0) return
    status = int(c_silc_context_rank(ctx, r, p))
    if (status == 0) then
      rank = int(r)
      size = int(p)
    end if
  end function silc_rank

  !> Deposits this rank's rows first_row..first_row+size(x)-1 (1-based) of the
  !> vector name; the ranks' blocks, in rank order, tile the whole vector.
  integer function put_rows_vector(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer, intent(in) :: first_row
    real(c_double), intent(in) :: x(:)
    own_failure = .false.
    status = put_rows_dense(name, int(first_row, c_int64_t), int(size(x), c_int64_t), 1_c_int64_t, x)
  end function put_rows_vector

  integer function put_rows_vector_int64(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: first_row
    real(c_double), intent(in) :: x(:)
    own_failure = .false.
    status = put_rows_dense(name, first_row, int(size(x), c_int64_t), 1_c_int64_t, x)
  end function put_rows_vector_int64

  !> A dense block: this rank's size(x, 1) rows, all size(x, 2) columns.
  integer function put_rows_matrix(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer, intent(in) :: first_row
    real(c_double), intent(in) :: x(:, :)
    own_failure = .false.
    status = put_rows_dense(name, int(first_row, c_int64_t), int(size(x, 1), c_int64_t), &
                            int(size(x, 2), c_int64_t), x)
  end function put_rows_matrix

  integer function put_rows_matrix_int64(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: first_row
    real(c_double), intent(in) :: x(:, :)
    own_failure = .false.
    status = put_rows_dense(name, first_row, int(size(x, 1), c_int64_t), int(size(x, 2), c_int64_t), x)
  end function put_rows_matrix_int64

  ! The CSR row wrappers' one worker: copies the block's 1-based index arrays
  ! (put_csr_0based makes them 0-based in place, and a program's arrays are
  ! intent(in)) and puts them with real or complex values.
  integer function put_rows_csr_copy(name, first_row, m, n, rowptr, colind, values, zvalues) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: first_row, m, n, rowptr(:), colind(:)
    real(c_double), intent(in), optional :: values(:)
    complex(c_double_complex), intent(in), optional :: zvalues(:)
    integer(c_int64_t), allocatable :: rp(:), ci(:)
    own_failure = .false.
    allocate(rp(size(rowptr)), ci(size(colind)))
    rp(:) = rowptr
    ci(:) = colind
    status = put_csr_0based(name, m, n, rp, ci, first_row, values=values, zvalues=zvalues)
  end function put_rows_csr_copy

  !> A CSR block: this rank's m rows (first_row..first_row+m-1) of a matrix
  !> with n columns, as 1-based CSR of the block (rowptr(1) = 1, m+1 entries)
  !> with global column indices 1..n.
  integer function put_rows_csr_int(name, first_row, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer, intent(in) :: first_row, m, n, rowptr(:), colind(:)
    real(c_double), intent(in) :: values(:)
    status = put_rows_csr_copy(name, int(first_row, c_int64_t), int(m, c_int64_t), int(n, c_int64_t), &
                               int(rowptr, c_int64_t), int(colind, c_int64_t), values=values)
  end function put_rows_csr_int

  integer function put_rows_csr_int64(name, first_row, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: first_row, m, n, rowptr(:), colind(:)
    real(c_double), intent(in) :: values(:)
    status = put_rows_csr_copy(name, first_row, m, n, rowptr, colind, values=values)
  end function put_rows_csr_int64

  !> The complex blocks: as the real ones above, complex(c_double_complex) values.
  integer function put_rows_vector_complex(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer, intent(in) :: first_row
    complex(c_double_complex), intent(in) :: x(:)
    own_failure = .false.
    status = put_rows_dense(name, int(first_row, c_int64_t), int(size(x), c_int64_t), 1_c_int64_t, z=x)
  end function put_rows_vector_complex

  integer function put_rows_vector_int64_complex(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: first_row
    complex(c_double_complex), intent(in) :: x(:)
    own_failure = .false.
    status = put_rows_dense(name, first_row, int(size(x), c_int64_t), 1_c_int64_t, z=x)
  end function put_rows_vector_int64_complex

  integer function put_rows_matrix_complex(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer, intent(in) :: first_row
    complex(c_double_complex), intent(in) :: x(:, :)
    own_failure = .false.
    status = put_rows_dense(name, int(first_row, c_int64_t), int(size(x, 1), c_int64_t), &
                            int(size(x, 2), c_int64_t), z=x)
  end function put_rows_matrix_complex

  integer function put_rows_matrix_int64_complex(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: first_row
    complex(c_double_complex), intent(in) :: x(:, :)
    own_failure = .false.
    status = put_rows_dense(name, first_row, int(size(x, 1), c_int64_t), int(size(x, 2), c_int64_t), z=x)
  end function put_rows_matrix_int64_complex

  integer function put_rows_csr_int_complex(name, first_row, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer, intent(in) :: first_row, m, n, rowptr(:), colind(:)
    complex(c_double_complex), intent(in) :: values(:)
    status = put_rows_csr_copy(name, int(first_row, c_int64_t), int(m, c_int64_t), int(n, c_int64_t), &
                               int(rowptr, c_int64_t), int(colind, c_int64_t), zvalues=values)
  end function put_rows_csr_int_complex

  integer function put_rows_csr_int64_complex(name, first_row, m, n, rowptr, colind, values) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: first_row, m, n, rowptr(:), colind(:)
    complex(c_double_complex), intent(in) :: values(:)
    status = put_rows_csr_copy(name, first_row, m, n, rowptr, colind, zvalues=values)
  end function put_rows_csr_int64_complex

  !> Fetches this rank's rows of the vector name into x, allocated (or
  !> reallocated) here, and the first of them (1-based) into first_row: a
  !> value computed from distributed operands keeps their rows, a whole value
  !> is split evenly.  On one process x is the whole vector, first_row 1.
  integer function get_rows_vector(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer, intent(out) :: first_row
    real(c_double), allocatable, intent(inout) :: x(:)
    integer(c_int64_t) :: first
    first_row = 0
    status = get_rows_into(name, first, x=x)
    if (status == 0) status = narrow_first_row(name, first, size(x, kind=c_int64_t), first_row)
  end function get_rows_vector

  integer function get_rows_vector_int64(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(out) :: first_row
    real(c_double), allocatable, intent(inout) :: x(:)
    status = get_rows_into(name, first_row, x=x)
  end function get_rows_vector_int64

  !> This rank's rows of a matrix (dense, or sparse made dense) into x(:, :),
  !> allocated here with the block's shape.
  integer function get_rows_matrix(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer, intent(out) :: first_row
    real(c_double), allocatable, intent(inout) :: x(:, :)
    integer(c_int64_t) :: first
    first_row = 0
    status = get_rows_into(name, first, x2=x)
    if (status == 0) status = narrow_first_row(name, first, size(x, 1, kind=c_int64_t), first_row)
  end function get_rows_matrix

  integer function get_rows_matrix_int64(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(out) :: first_row
    real(c_double), allocatable, intent(inout) :: x(:, :)
    status = get_rows_into(name, first_row, x2=x)
  end function get_rows_matrix_int64

  !> The same into complex(c_double_complex) arrays: a complex value's rows,
  !> or a real value's with imaginary parts 0.
  integer function get_rows_vector_complex(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer, intent(out) :: first_row
    complex(c_double_complex), allocatable, intent(inout) :: x(:)
    integer(c_int64_t) :: first
    first_row = 0
    status = get_rows_into(name, first, z=x)
    if (status == 0) status = narrow_first_row(name, first, size(x, kind=c_int64_t), first_row)
  end function get_rows_vector_complex

  integer function get_rows_vector_int64_complex(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(out) :: first_row
    complex(c_double_complex), allocatable, intent(inout) :: x(:)
    status = get_rows_into(name, first_row, z=x)
  end function get_rows_vector_int64_complex

  integer function get_rows_matrix_complex(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer, intent(out) :: first_row
    complex(c_double_complex), allocatable, intent(inout) :: x(:, :)
    integer(c_int64_t) :: first
    first_row = 0
    status = get_rows_into(name, first, z2=x)
    if (status == 0) status = narrow_first_row(name, first, size(x, 1, kind=c_int64_t), first_row)
  end function get_rows_matrix_complex

  integer function get_rows_matrix_int64_complex(name, first_row, x) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(out) :: first_row
    complex(c_double_complex), allocatable, intent(inout) :: x(:, :)
    status = get_rows_into(name, first_row, z2=x)
  end function get_rows_matrix_int64_complex

  ! first_row for a default-integer caller: an error when the block's rows
  ! (first .. first + rows - 1) do not all fit a default integer.
  integer function narrow_first_row(name, first, rows, first_row) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: first, rows
    integer, intent(out) :: first_row
    status = 0
    first_row = 0
    if (first + rows - 1 > huge(first_row)) then
      status = fail('silc_get_rows: the rows of ''' // trim(name) // ''' go beyond ' // &
                    int_text(int(huge(first_row), c_int64_t)) // '; use an integer(c_int64_t) first_row')
    else
      first_row = int(first)
    end if
  end function narrow_first_row

  ! Every silc_get_rows: this rank's rows of name into the one array given
  ! (x, x2 real 1-D or 2-D; z, z2 complex), allocated (or reallocated) here
  ! with the block's shape, and the first row (1-based).  A complex array
  ! asks for either field (silc_get_rows_complex), a real one for a real
  ! value only (silc_get_rows refuses a complex one, naming it).
  integer function get_rows_into(name, first_row, x, x2, z, z2) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(out) :: first_row
    real(c_double), allocatable, intent(inout), optional :: x(:), x2(:, :)
    complex(c_double_complex), allocatable, intent(inout), optional :: z(:), z2(:, :)
    type(silc_envelope_t) :: e
    own_failure = .false.
    first_row = 0
    status = get_rows_envelope(name, present(x) .or. present(z), present(z) .or. present(z2), e, first_row)
    if (status /= 0) return
    if (present(x)) then
      if (allocated(x)) deallocate(x)
      allocate(x(e%m))
      status = int(c_envelope_to_dense(e, x))
    else if (present(x2)) then
      if (allocated(x2)) deallocate(x2)
      allocate(x2(e%m, e%n))
      status = int(c_envelope_to_dense(e, x2))
    else if (present(z)) then
      if (allocated(z)) deallocate(z)
      allocate(z(e%m))
      status = envelope_to_complex(e, e%m, z)
    else if (present(z2)) then
      if (allocated(z2)) deallocate(z2)
      allocate(z2(e%m, e%n))
      status = envelope_to_complex(e, e%m * e%n, z2)
    end if
    call c_envelope_free(e)
  end function get_rows_into

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

  integer function put_dense_complex(name, m, n, x) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: m, n
    complex(c_double_complex), intent(in) :: x(*)
    type(silc_envelope_t) :: e
    e = empty_envelope()
    status = int(c_envelope_dense_complex(e, m, n, x))
    if (status == 0) status = put_envelope(name, e)
  end function put_dense_complex

  ! Deposits e and frees it whatever happens.
  integer function put_envelope(name, e) result(status)
    character(len=*), intent(in) :: name
    type(silc_envelope_t), intent(inout) :: e
    status = int(c_silc_put(c_string(name), e))
    call c_envelope_free(e)
  end function put_envelope

  ! Checks 1-based CSR, so a mistake is reported in the caller's own indices,
  ! then shifts rp and ci to 0-based in place and deposits: the whole value,
  ! or with first (1-based) the block of rows first..first+m-1 (silc_put_rows).
  ! The values are real (values) or complex (zvalues): one of them is given.
  integer function put_csr_0based(name, m, n, rp, ci, first, values, zvalues) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: m, n
    integer(c_int64_t), intent(inout) :: rp(:), ci(:)
    integer(c_int64_t), intent(in), optional :: first
    real(c_double), intent(in), optional :: values(:)
    complex(c_double_complex), intent(in), optional :: zvalues(:)
    type(silc_envelope_t) :: e
    integer(c_int64_t) :: nvalues

    if (present(zvalues)) then
      nvalues = size(zvalues, kind=c_int64_t)
    else
      nvalues = size(values, kind=c_int64_t)
    end if
    if (present(first)) then
      status = check_csr('silc_put_rows: ', m, n, rp, ci, nvalues)
      if (status /= 0) then
        call spoil_put_rows(name)
        return
      end if
    else
      status = check_csr('silc_put_csr: ', m, n, rp, ci, nvalues)
      if (status /= 0) return
    end if
    rp = rp - 1
    ci = ci - 1
    e = empty_envelope()
    ! colind/values may be empty: the C side reads nnz = rp(m+1) entries, none.
    if (present(zvalues)) then
      status = int(c_envelope_csr_complex(e, m, n, rp, ci, zvalues))
    else
      status = int(c_envelope_csr(e, m, n, rp, ci, values))
    end if
    if (present(first)) then
      status = put_rows_envelope(name, first, e, status)
    else if (status == 0) then
      status = put_envelope(name, e)
    end if
  end function put_csr_0based

  ! The checks of put_csr_0based (nvalues: the size of the values array),
  ! messages prefixed with who.
  integer function check_csr(who, m, n, rp, ci, nvalues) result(status)
    character(len=*), intent(in) :: who
    integer(c_int64_t), intent(in) :: m, n, rp(:), ci(:), nvalues
    integer(c_int64_t) :: i, k, nnz
    integer(c_int64_t), allocatable :: seen(:)

    status = 0
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
    if (size(ci, kind=c_int64_t) < nnz .or. nvalues < nnz) then
      status = fail(who // 'rowptr(m+1) - 1 = ' // int_text(nnz) // ' entries but colind has ' // &
                    int_text(size(ci, kind=c_int64_t)) // ' and values ' // int_text(nvalues))
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
  end function check_csr

  ! The default context, or a failure naming who if silc_init has not opened it.
  integer function default_context(who, ctx) result(status)
    character(len=*), intent(in) :: who
    type(c_ptr), intent(out) :: ctx
    status = 0
    ctx = c_silc_default_context()
    if (.not. c_associated(ctx)) status = fail(who // 'silc_init has not been called')
  end function default_context

  ! A dense block of m x n values, real (x) or complex (z): one of them given.
  integer function put_rows_dense(name, first, m, n, x, z) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: first, m, n
    real(c_double), intent(in), optional :: x(*)
    complex(c_double_complex), intent(in), optional :: z(*)
    type(silc_envelope_t) :: e
    e = empty_envelope()
    if (present(z)) then
      status = int(c_envelope_dense_complex(e, m, n, z))
    else
      status = int(c_envelope_dense(e, m, n, x))
    end if
    status = put_rows_envelope(name, first, e, status)
  end function put_rows_dense

  ! Deposits e as the rows first.. (1-based) of name and frees it whatever
  ! happens.  status_in is the verdict so far (nonzero: building e failed):
  ! a failure still makes the collective call, through spoil_put_rows.
  integer function put_rows_envelope(name, first, e, status_in) result(status)
    character(len=*), intent(in) :: name
    integer(c_int64_t), intent(in) :: first
    type(silc_envelope_t), intent(inout) :: e
    integer, intent(in) :: status_in
    type(c_ptr) :: ctx
    status = status_in
    if (status == 0 .and. first < 1) &
      status = fail('silc_put_rows ''' // trim(name) // ''': first_row is ' // int_text(first) // &
                    ', but rows are numbered from 1 (the value''s first row is 1)')
    if (status /= 0) then
      call spoil_put_rows(name)
    else
      status = default_context('silc_put_rows: ', ctx)
      if (status == 0) status = int(c_silc_put_rows(ctx, c_string(name), first - 1, e))
    end if
    call c_envelope_free(e)
  end function put_rows_envelope

  ! After a failure found here, makes the call the other ranks of an SPMD
  ! context are making too (with a row number the library refuses), so that
  ! they fail with this rank instead of waiting for it; this rank keeps its
  ! own message.
  subroutine spoil_put_rows(name)
    character(len=*), intent(in) :: name
    character(len=:), allocatable :: msg
    type(c_ptr) :: ctx
    type(silc_envelope_t) :: none
    integer :: ignored
    msg = silc_errmsg()
    ctx = c_silc_default_context()
    if (c_associated(ctx)) then
      none = empty_envelope()
      ignored = int(c_silc_put_rows(ctx, c_string(name), -1_c_int64_t, none))
    end if
    ignored = fail(msg)
  end subroutine spoil_put_rows

  ! Fetches this rank's rows of name (e to be freed by the caller on success)
  ! and the first of them, 1-based; a vector must have one column.  A real
  ! value only, or either field when accept_complex.
  integer function get_rows_envelope(name, vector, accept_complex, e, first) result(status)
    character(len=*), intent(in) :: name
    logical, intent(in) :: vector, accept_complex
    type(silc_envelope_t), intent(out) :: e
    integer(c_int64_t), intent(out) :: first
    type(c_ptr) :: ctx
    integer(c_int64_t) :: first0
    e = empty_envelope()
    first = 0
    status = default_context('silc_get_rows: ', ctx)
    if (status /= 0) return
    if (accept_complex) then
      status = int(c_silc_get_rows_complex(ctx, e, first0, c_string(name)))
    else
      status = int(c_silc_get_rows(ctx, e, first0, c_string(name)))
    end if
    if (status /= 0) return
    if (vector .and. e%n /= 1) then
      status = fail('silc_get_rows: ''' // trim(name) // ''' has ' // int_text(e%n) // &
                    ' columns, not 1; fetch its rows into an allocatable 2-D array')
      call c_envelope_free(e)
      return
    end if
    first = first0 + 1
  end function get_rows_envelope

  ! Fetches name into e: a real value only (SILC_GET refuses a complex one,
  ! naming it), or either field when accept_complex (silc_get_complex on
  ! the default context).
  integer function get_envelope(name, e, accept_complex) result(status)
    character(len=*), intent(in) :: name
    type(silc_envelope_t), intent(out) :: e
    logical, intent(in), optional :: accept_complex
    type(c_ptr) :: ctx
    e = empty_envelope()
    status = 0
    if (present(accept_complex)) then
      if (accept_complex) then
        status = default_context('silc_get: ', ctx)
        if (status == 0) status = int(c_silc_get_complex(ctx, e, c_string(name)))
        return
      end if
    end if
    status = int(c_silc_get(e, c_string(name)))
  end function get_envelope

  logical function is_complex(e)
    type(silc_envelope_t), intent(in) :: e
    is_complex = iand(int(e%format), int(SILC_COMPLEX)) /= 0
  end function is_complex

  ! Fetches name into x(1:m*n) if its shape is m x n (or n x m for a vector,
  ! when either_way); otherwise fails naming both shapes.
  integer function get_dense(name, m, n, either_way, what, x) result(status)
    character(len=*), intent(in) :: name, what
    integer(c_int64_t), intent(in) :: m, n
    logical, intent(in) :: either_way
    real(c_double), intent(inout) :: x(*)
    type(silc_envelope_t) :: e
    status = get_envelope(name, e)
    if (status /= 0) return
    status = shape_fits(name, e, m, n, either_way, what)
    if (status == 0) status = int(c_envelope_to_dense(e, x))
    call c_envelope_free(e)
  end function get_dense

  ! get_dense for a complex array: a complex value, or a real one with
  ! imaginary parts 0.
  integer function get_dense_complex(name, m, n, either_way, what, x) result(status)
    character(len=*), intent(in) :: name, what
    integer(c_int64_t), intent(in) :: m, n
    logical, intent(in) :: either_way
    complex(c_double_complex), intent(inout) :: x(*)
    type(silc_envelope_t) :: e
    status = get_envelope(name, e, accept_complex=.true.)
    if (status /= 0) return
    status = shape_fits(name, e, m, n, either_way, what)
    if (status == 0) status = envelope_to_complex(e, m * n, x)
    call c_envelope_free(e)
  end function get_dense_complex

  ! The count entries of e (dense, or made dense) into x: a complex
  ! envelope's as they are, a real one's with imaginary parts 0.  Through a
  ! buffer of doubles (silc_envelope_to_dense takes doubles: 2 an entry when
  ! complex).
  integer function envelope_to_complex(e, count, x) result(status)
    type(silc_envelope_t), intent(in) :: e
    integer(c_int64_t), intent(in) :: count
    complex(c_double_complex), intent(inout) :: x(*)
    real(c_double), allocatable :: buf(:)
    if (is_complex(e)) then
      allocate(buf(2 * count))
      status = int(c_envelope_to_dense(e, buf))
      if (status == 0) x(1:count) = cmplx(buf(1::2), buf(2::2), c_double_complex)
    else
      allocate(buf(count))
      status = int(c_envelope_to_dense(e, buf))
      if (status == 0) x(1:count) = cmplx(buf, 0.0_c_double, c_double_complex)
    end if
  end function envelope_to_complex

  ! 0 if e (the value of name) is m x n (or n x m for a vector, when
  ! either_way); otherwise a failure naming both shapes.
  integer function shape_fits(name, e, m, n, either_way, what) result(status)
    character(len=*), intent(in) :: name, what
    type(silc_envelope_t), intent(in) :: e
    integer(c_int64_t), intent(in) :: m, n
    logical, intent(in) :: either_way
    logical :: fits
    status = 0
    fits = e%m == m .and. e%n == n
    if (either_way) fits = fits .or. (min(e%m, e%n) <= 1 .and. e%m * e%n == m * n)
    if (.not. fits) &
      status = fail('silc_get: ''' // trim(name) // ''' is ' // &
                    shape_text(c_envelope_rows(e), c_envelope_cols(e)) // ' but was asked into ' // &
                    what // '; allocate it after silc_get_shape(name, m, n)')
  end function shape_fits

  ! Fetches a CSR value; rp and ci point into e (0-based) until it is freed,
  ! the values are already copied out: into values (a real value only), or
  ! into zvalues (either field; a real value's imaginary parts 0).
  integer function get_csr_envelope(name, e, rp, ci, values, zvalues) result(status)
    character(len=*), intent(in) :: name
    type(silc_envelope_t), intent(out) :: e
    integer(c_int64_t), pointer, intent(out) :: rp(:), ci(:)
    real(c_double), allocatable, intent(inout), optional :: values(:)
    complex(c_double_complex), allocatable, intent(inout), optional :: zvalues(:)
    real(c_double), pointer :: v(:)
    complex(c_double_complex), pointer :: z(:)
    integer :: base
    nullify(rp, ci)
    status = get_envelope(name, e, accept_complex=present(zvalues))
    if (status /= 0) return
    base = iand(int(e%format), not(int(SILC_COMPLEX)))
    if (base /= SILC_CSR) then
      status = fail('silc_get_csr: ''' // trim(name) // ''' is a ' // shape_text(e%m, e%n) // ' ' // &
                    trim(merge('dense', 'band ', base == SILC_DENSE)) // &
                    ' matrix, not sparse; fetch it into a 2-D array with silc_get')
      call c_envelope_free(e)
      return
    end if
    call c_f_pointer(e%rowptr, rp, [e%m + 1])
    call c_f_pointer(e%colind, ci, [e%nnz])
    if (present(zvalues)) then
      if (allocated(zvalues)) deallocate(zvalues)
      if (is_complex(e)) then
        call c_f_pointer(e%values, z, [e%nnz])
        zvalues = z
      else
        call c_f_pointer(e%values, v, [e%nnz])
        zvalues = cmplx(v, 0.0_c_double, c_double_complex)
      end if
    else
      call c_f_pointer(e%values, v, [e%nnz])
      if (allocated(values)) deallocate(values)
      values = v
    end if
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
