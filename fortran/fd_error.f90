!> Error handling: library routines never stop or print; they allocate an error_type
!> (the last argument) and return. Failure means "allocated".
module fd_error
   implicit none
   private

   public :: error_type, fatal_error, fmt_real, fmt_int

   !> An error raised by the library, handed back to the caller.
   type :: error_type
      integer :: stat = 1                       !! non-zero status code
      character(len=:), allocatable :: message  !! what went wrong, naming the offending input
   end type error_type

contains

   !> Create an error with a message (and an optional status code).
   subroutine fatal_error(error, message, stat)
      type(error_type), allocatable, intent(out) :: error !! the error to create
      character(len=*), intent(in) :: message            !! message naming the offending input
      integer, intent(in), optional :: stat              !! status code (default 1)

      allocate (error)
      error%message = message
      if (present(stat)) error%stat = stat
   end subroutine fatal_error

   !> A real number as short text, for messages.
   pure function fmt_real(x) result(str)
      use fd_kinds, only: dp
      real(dp), intent(in) :: x               !! value to format
      character(len=:), allocatable :: str    !! the value as text
      character(len=32) :: buf

      write (buf, '(g0)') x
      str = trim(adjustl(buf))
   end function fmt_real

   !> An integer as text, for messages.
   pure function fmt_int(i) result(str)
      integer, intent(in) :: i                !! value to format
      character(len=:), allocatable :: str    !! the value as text
      character(len=16) :: buf

      write (buf, '(i0)') i
      str = trim(buf)
   end function fmt_int

end module fd_error
