!> Reader of recorded table motion: one value a line, or time-value columns, sampled at
!> dt_record. Displacement records are turned into accelerations by second differences.
module fd_record
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real
   use fd_textio, only: line_type, read_text_file, split_tokens
   implicit none
   private

   public :: read_record

contains

   !> Read a record file and return the table acceleration at k*dt_record, k = 0, 1, ...
   !> Blank lines and lines starting with '#' or '!' are skipped.
   subroutine read_record(path, is_displacement, scale, dt_record, acc, error)
      character(len=*), intent(in) :: path            !! record file
      logical, intent(in) :: is_displacement          !! the record holds displacements [m]
      real(dp), intent(in) :: scale                   !! factor applied to every value
      real(dp), intent(in) :: dt_record               !! sampling step of the record [s]
      real(dp), allocatable, intent(out) :: acc(:)    !! table acceleration samples [m/s2]
      type(error_type), allocatable, intent(out) :: error !! bad file, line or value
      type(line_type), allocatable :: lines(:), tok(:)
      real(dp), allocatable :: val(:), tim(:)
      real(dp) :: x
      integer :: i, k, n, ncol, ios
      character(len=:), allocatable :: where, first

      call read_text_file(path, lines, error)
      if (allocated(error)) return
      allocate (val(size(lines)), tim(size(lines)))
      n = 0
      ncol = 0
      do i = 1, size(lines)
         first = adjustl(lines(i)%s)
         if (len_trim(first) == 0) cycle
         if (first(1:1) == '#' .or. first(1:1) == '!') cycle
         where = "record file '"//path//"', line "//trim(fmt_int(i))
         call split_tokens(lines(i)%s, tok)
         if (ncol == 0) ncol = size(tok)
         if (size(tok) /= ncol .or. ncol > 2) then
            call fatal_error(error, where//": expected "//trim(fmt_int(min(ncol, 2)))// &
                             " column(s) (value, or time and value), found "//trim(fmt_int(size(tok))))
            return
         end if
         n = n + 1
         do k = 1, ncol
            read (tok(k)%s, *, iostat=ios) x
            if (ios /= 0) then
               call fatal_error(error, where//": '"//tok(k)%s//"' is not a number")
               return
            end if
            if (.not. ieee_is_finite(x)) then
               call fatal_error(error, where//": value '"//tok(k)%s//"' is not finite")
               return
            end if
            if (k == ncol) then
               val(n) = x
            else
               tim(n) = x
            end if
         end do
         if (ncol == 2 .and. n > 1) then
            if (abs(tim(n) - tim(1) - (n - 1)*dt_record) > 1.0e-6_dp*dt_record + &
                1.0e-9_dp*abs(tim(n))) then
               call fatal_error(error, where//": time "//tok(1)%s//" is not on the grid of dt_record = " &
                                //trim(fmt_real(dt_record))//" s starting at "//trim(fmt_real(tim(1)))//" s")
               return
            end if
         end if
      end do
      if (n < 2 .or. (is_displacement .and. n < 4)) then
         call fatal_error(error, "record file '"//path//"' has "//trim(fmt_int(n))// &
                          " samples; at least "//trim(fmt_int(merge(4, 2, is_displacement)))//" are needed")
         return
      end if
      val = scale*val(1:n)
      if (is_displacement) then
         allocate (acc(n))
         acc(2:n - 1) = (val(3:n) - 2.0_dp*val(2:n - 1) + val(1:n - 2))/dt_record**2
         acc(1) = (2.0_dp*val(1) - 5.0_dp*val(2) + 4.0_dp*val(3) - val(4))/dt_record**2
         acc(n) = (2.0_dp*val(n) - 5.0_dp*val(n - 1) + 4.0_dp*val(n - 2) - val(n - 3))/dt_record**2
      else
         acc = val
      end if
   end subroutine read_record

end module fd_record
