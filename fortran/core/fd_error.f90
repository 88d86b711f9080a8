!> Error handling: library routines never stop or print; they allocate an error_type
!> (the last argument) and return. Failure means "allocated".
module fd_error
   implicit none
   private

   public :: error_type, fatal_error, fmt_real, fmt_int, fmt_text, stat_no_memory, stat_output, echo_chars
   public :: allocation_error

   !> The stat of an error raised because memory could not be had (an allocation the size
   !> of the input failed): the caller may tell it from a bad input.
   integer, parameter :: stat_no_memory = 5

   !> The stat of an error raised because a file could not be written (its system reason:
   !> a full disk, a quota, a file-size limit, a permission): the caller may tell it from a
   !> bad input or a failure of the solver, whichever step met it.
   integer, parameter :: stat_output = 4

   !> Characters of a text a message echoes (a value, a line of a file); a longer text is cut
   !> there and its length said: a megabyte value makes a line of a message, not a megabyte.
   integer, parameter :: echo_chars = 80

   !> An error raised by the library, handed back to the caller.
   type :: error_type
      integer :: stat = 1                       !! non-zero status code
      character(len=:), allocatable :: message  !! what went wrong, naming the offending input
   end type error_type

contains

   !> Create an error with a message (and an optional status code).
   pure subroutine fatal_error(error, message, stat)
      type(error_type), allocatable, intent(out) :: error !! the error to create
      character(len=*), intent(in) :: message            !! message naming the offending input
      integer, intent(in), optional :: stat              !! status code (default 1)

      allocate (error)
      error%message = message
      if (present(stat)) error%stat = stat
   end subroutine fatal_error

   !> The error of an allocate statement whose stat is not 0: "not enough memory for " what,
   !> with stat_no_memory; none (error not allocated) when stat is 0.
   pure subroutine allocation_error(error, stat, what)
      type(error_type), allocatable, intent(out) :: error !! set when stat /= 0
      integer, intent(in) :: stat                        !! the allocate statement's stat
      character(len=*), intent(in) :: what               !! what the memory was for

      if (stat /= 0) call fatal_error(error, "not enough memory for "//what, stat_no_memory)
   end subroutine allocation_error

   !> A real number as short text, for messages: the fewest significant digits that
   !> read back to the same value, in fixed notation when that is short.
   pure function fmt_real(x) result(str)
      use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
      use fd_kinds, only: dp
      real(dp), intent(in) :: x               !! value to format
      character(len=32) :: str                !! the value as text, left-adjusted
      character(len=40) :: buf, fmt
      character(len=:), allocatable :: w
      real(dp) :: y
      integer :: p, e, d, ios

      if (.not. ieee_is_finite(x)) then
         write (buf, '(g0)') x
         str = trim(adjustl(buf))
         return
      end if
      if (x == 0.0_dp) then
         str = '0'
         return
      end if
      do p = 1, 17
         write (fmt, '(a,i0,a)') '(es30.', p - 1, 'e3)'
         write (buf, fmt) x
         read (buf, *, iostat=ios) y
         if (ios == 0 .and. y == x) exit
      end do
      p = min(p, 17)
      e = floor(log10(abs(x)))
      if (e >= -4 .and. e < 15) then
         d = max(1, p - 1 - e)
         write (fmt, '(a,i0,a)') '(f0.', d, ')'
         write (buf, fmt) x
         w = trim(adjustl(buf))
         do while (len(w) > 1 .and. w(len(w):len(w)) == '0')
            w = w(1:len(w) - 1)
         end do
         if (w(len(w):len(w)) == '.') w = w//'0'
         if (w(1:1) == '.') w = '0'//w
         if (w(1:2) == '-.') w = '-0'//w(2:)
      else
         ! mantissa without trailing zeros, exponent without padding: -1.5E-5
         w = trim(adjustl(buf))
         e = index(w, 'E')
         read (w(e + 1:), *) d
         w = w(1:e - 1)
         do while (w(len(w):len(w)) == '0')
            w = w(1:len(w) - 1)
         end do
         if (w(len(w):len(w)) == '.') w = w//'0'
         write (buf, '(i0)') d
         w = w//'E'//trim(buf)
      end if
      str = w
   end function fmt_real

   !> A text as a message echoes it: its first echo_chars characters (UTF-8 characters, never
   !> cut inside one), then '... (N characters)' when it is longer; control characters shown
   !> as '?'. Trailing blanks are dropped (trim the result where it is used).
   pure function fmt_text(text) result(str)
      character(len=*), intent(in) :: text    !! the text to echo
      character(len=4*echo_chars + 32) :: str !! as shown
      integer :: i, n, chars, last

      n = len_trim(text)
      chars = 0
      last = 0
      do i = 1, n
         if (iand(iachar(text(i:i)), 192) == 128) cycle   ! a UTF-8 continuation byte
         chars = chars + 1
         if (chars <= echo_chars) last = i
      end do
      if (chars > echo_chars) then
         ! the last character kept ends before the first byte of the next one
         do i = last + 1, n
            if (iand(iachar(text(i:i)), 192) /= 128) exit
            last = i
         end do
      else
         last = n
      end if
      str = text(1:min(last, 4*echo_chars))
      do i = 1, min(last, 4*echo_chars)
         if (iachar(str(i:i)) < 32 .or. iachar(str(i:i)) == 127) str(i:i) = '?'
      end do
      if (chars > echo_chars) then
         str = str(1:min(last, 4*echo_chars))//'... ('//trim(fmt_int(chars))//' characters)'
      else if (last > 4*echo_chars) then   ! bytes that are no UTF-8 text
         str = str(1:4*echo_chars)//'... ('//trim(fmt_int(n))//' bytes)'
      end if
   end function fmt_text

   !> An integer as text, for messages.
   pure function fmt_int(i) result(str)
      integer, intent(in) :: i                !! value to format
      character(len=16) :: str                !! the value as text, left-adjusted
      character(len=11) :: digits
      integer :: k, m, q

      ! the digits of -|i| (every 32-bit integer has one, -huge(i) - 1 included), without an
      ! internal write: the deck reader and the result's set-up format a few hundred of them,
      ! and an internal write costs some 4000 instructions
      if (i < 0) then
         m = i
      else
         m = -i
      end if
      k = len(digits) + 1
      do
         q = m/10
         k = k - 1
         digits(k:k) = achar(iachar('0') + (10*q - m))
         m = q
         if (m == 0) exit
      end do
      if (i < 0) then
         k = k - 1
         digits(k:k) = '-'
      end if
      str = digits(k:)
   end function fmt_int

end module fd_error
