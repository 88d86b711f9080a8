!> Unit tests of the number formatting used in every message (fd_error): the shortest
!> text that reads back to the same value; and the error of a failed allocation.
module test_fd_format
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_error, only: fmt_real, fmt_int, fd_error_type => error_type, allocation_error, stat_no_memory
   implicit none
   private

   public :: collect_format

contains

   subroutine collect_format(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("short values", test_short), &
                  new_unittest("round trip", test_round_trip), &
                  new_unittest("exponent form", test_exponent), &
                  new_unittest("integers", test_int), &
                  new_unittest("a failed allocation's error", test_allocation_error) &
                  ]
   end subroutine collect_format

   subroutine test_short(error)
      type(error_type), allocatable, intent(out) :: error

      call check(error, trim(fmt_real(0.0_dp)), '0')
      if (allocated(error)) return
      call check(error, trim(fmt_real(61.81_dp)), '61.81')
      if (allocated(error)) return
      call check(error, trim(fmt_real(-0.25_dp)), '-0.25')
      if (allocated(error)) return
      call check(error, trim(fmt_real(1.0e-3_dp)), '0.001')
      if (allocated(error)) return
      call check(error, trim(fmt_real(3.0_dp)), '3.0')
   end subroutine test_short

   !> Every value formatted reads back to itself (17 significant digits at most).
   subroutine test_round_trip(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: x, y
      character(len=32) :: text
      integer :: i

      do i = -300, 300, 7
         x = 1.2345678901234567_dp*10.0_dp**i/3.0_dp
         text = fmt_real(x)
         read (text, *) y
         call check(error, y == x, 'fmt_real('//trim(fmt_real(x))//') does not read back exactly')
         if (allocated(error)) return
      end do
   end subroutine test_round_trip

   subroutine test_exponent(error)
      type(error_type), allocatable, intent(out) :: error

      call check(error, trim(fmt_real(-1.5e-5_dp)), '-1.5E-5')
      if (allocated(error)) return
      call check(error, trim(fmt_real(1.0e300_dp)), '1.0E300')
   end subroutine test_exponent

   subroutine test_int(error)
      type(error_type), allocatable, intent(out) :: error

      call check(error, trim(fmt_int(-42)), '-42')
      if (allocated(error)) return
      call check(error, trim(fmt_int(huge(1))), '2147483647')
      if (allocated(error)) return
      call check(error, trim(fmt_int(-huge(1) - 1)), '-2147483648')
      if (allocated(error)) return
      call check(error, trim(fmt_int(0)), '0')
      if (allocated(error)) return
      call same_as_write(error)
   end subroutine test_int

   !> fmt_int against the processor's own i0 edit descriptor, over every power of ten and
   !> its neighbours, both signs.
   subroutine same_as_write(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=16) :: ref
      integer :: p, d, x

      x = 1
      do p = 0, 9
         do d = -1, 1
            write (ref, '(i0)') x + d
            call check(error, trim(fmt_int(x + d)), trim(ref))
            if (allocated(error)) return
            write (ref, '(i0)') -(x + d)
            call check(error, trim(fmt_int(-(x + d))), trim(ref))
            if (allocated(error)) return
         end do
         if (p < 9) x = 10*x
      end do
   end subroutine same_as_write

   !> A failed allocation (stat /= 0): "not enough memory for " and what it was for, with
   !> stat_no_memory (the caller's OutOfMemoryError); stat 0: no error.
   subroutine test_allocation_error(error)
      type(error_type), allocatable, intent(out) :: error
      type(fd_error_type), allocatable :: err

      call allocation_error(err, 0, "the bands of 2 velocity-law devices")
      call check(error, .not. allocated(err), "an error for stat 0")
      if (allocated(error)) return
      call allocation_error(err, 5014, "the bands of 2 velocity-law devices")
      call check(error, allocated(err), "no error for stat 5014")
      if (allocated(error)) return
      call check(error, err%message, "not enough memory for the bands of 2 velocity-law devices")
      if (allocated(error)) return
      call check(error, err%stat == stat_no_memory, "the stat of a failed allocation")
   end subroutine test_allocation_error

end module test_fd_format
