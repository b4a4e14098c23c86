! diffusion1d_common.f90 -- what the two Fortran diffusion examples share
! (diffusion1d.f90 and its MPI form diffusion1d_mpi.f90): the command line,
! the rows of the shifted Laplacian I + c L, and C's %g for the summary line.
! Nothing here calls SILC or MPI; each program deposits the rows its own way.
module diffusion1d_common
  use, intrinsic :: iso_c_binding, only: c_double
  implicit none
  private
  public :: diff1d_parse_args, diff1d_laplacian_rows, diff1d_num

contains

  !> [N [steps [T [FILE]]]]: N and steps positive integers, T >= 0, FILE a
  !> path (receives the final u).  Arguments not given keep the caller's
  !> defaults; status 1 for a bad or extra argument.
  integer function diff1d_parse_args(n, steps, t_end, out_file) result(status)
    integer, intent(inout) :: n, steps
    real(c_double), intent(inout) :: t_end
    character(len=:), allocatable, intent(inout) :: out_file
    character(len=4096) :: arg
    integer :: nargs, length
    status = 0
    nargs = command_argument_count()
    if (nargs > 4) status = 1
    if (nargs >= 1 .and. status == 0) then
      call get_command_argument(1, arg)
      read (arg, *, iostat=status) n
      if (status == 0 .and. n < 1) status = 1
    end if
    if (nargs >= 2 .and. status == 0) then
      call get_command_argument(2, arg)
      read (arg, *, iostat=status) steps
      if (status == 0 .and. steps < 1) status = 1
    end if
    if (nargs >= 3 .and. status == 0) then
      call get_command_argument(3, arg)
      read (arg, *, iostat=status) t_end
      if (status == 0 .and. .not. (t_end >= 0)) status = 1
    end if
    if (nargs >= 4 .and. status == 0) then
      call get_command_argument(4, arg, length=length)
      if (length < 1 .or. length > len(arg)) status = 1
      out_file = trim(arg)
    end if
  end function diff1d_parse_args

  !> Rows first..first+rows-1 (1-based) of I + c L as 1-based CSR with
  !> global column numbers, L the second-difference matrix / h^2 on n points
  !> with zero Dirichlet ends; columns ascend within each row.  The whole
  !> matrix is first = 1, rows = n.
  subroutine diff1d_laplacian_rows(n, h, c, first, rows, rowptr, colind, values)
    integer, intent(in) :: n, first, rows
    real(c_double), intent(in) :: h, c
    integer, allocatable, intent(out) :: rowptr(:), colind(:)
    real(c_double), allocatable, intent(out) :: values(:)
    real(c_double) :: off
    integer :: j, k, nz
    allocate(rowptr(rows + 1), colind(3 * rows), values(3 * rows))
    off = c / h**2
    nz = 0
    do k = first, first + rows - 1
      rowptr(k - first + 1) = nz + 1
      do j = max(k - 1, 1), min(k + 1, n)
        nz = nz + 1
        colind(nz) = j
        values(nz) = merge(1 - 2 * off, off, j == k)
      end do
    end do
    rowptr(rows + 1) = nz + 1
  end subroutine diff1d_laplacian_rows

  !> A number as C's %g would print it: 0.5, 0.001, 2.000E-07.
  function diff1d_num(v) result(text)
    real(c_double), intent(in) :: v
    character(len=:), allocatable :: text
    character(len=32) :: buf
    if (abs(v) < tiny(v) .or. (abs(v) >= 1.0e-3_c_double .and. abs(v) < 1.0e6_c_double)) then
      write (buf, '(f0.6)') v
      text = trim(buf)
      do while (text(len(text):len(text)) == '0')
        text = text(:len(text) - 1)
      end do
      if (text(len(text):len(text)) == '.') text = text(:len(text) - 1)
      if (text(1:1) == '.') text = '0' // text
      if (text == '') text = '0'
    else
      write (buf, '(es10.3)') v
      text = trim(adjustl(buf))
    end if
  end function diff1d_num

end module diffusion1d_common
