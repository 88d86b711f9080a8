!> Unit tests of the strict number parser of the record reader (fd_record): decimal
!> numbers are read exactly as the compiler reads them; Fortran list-directed tokens,
!> NaN, infinities and malformed numbers are rejected.
module test_fd_record_parse
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_record, only: parse_real, units_factor, standard_gravity
   implicit none
   private

   public :: collect_record_parse

contains

   subroutine collect_record_parse(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("numbers read exactly", test_numbers), &
                  new_unittest("list-directed tokens rejected", test_rejected), &
                  new_unittest("NaN and infinity", test_nonfinite), &
                  new_unittest("units", test_units) &
                  ]
   end subroutine collect_record_parse

   !> Every accepted spelling gives the value the Fortran compiler gives the same literal.
   subroutine test_numbers(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=16), parameter :: tok(10) = [character(len=16) :: '0', '-1', '+2.5', '.0050', '-.1234567E-02', &
                                                 '1.', '6.02D23', '1e-300', '123456789012345', '0.1']
      real(dp), parameter :: val(10) = [0.0_dp, -1.0_dp, 2.5_dp, 0.005_dp, -0.1234567e-2_dp, 1.0_dp, 6.02e23_dp, &
                                        1.0e-300_dp, 123456789012345.0_dp, 0.1_dp]
      real(dp) :: x
      integer :: i, stat
      do i = 1, size(tok)
         call parse_real(trim(tok(i)), x, stat)
         call check(error, stat, 0, 'parse '//trim(tok(i)))
         if (allocated(error)) return
         call check(error, x == val(i), 'value of '//trim(tok(i)))
         if (allocated(error)) return
      end do
   end subroutine test_numbers

   !> What a list-directed read would take as a value (or as "keep the previous value").
   subroutine test_rejected(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=8), parameter :: tok(12) = [character(len=8) :: '/', '*', '3*', '3*0.5', '1.5-3', 'e5', '.', &
                                                '1e', '--1', '0x1p3', '1,5', 'T']
      real(dp) :: x
      integer :: i, stat
      do i = 1, size(tok)
         call parse_real(trim(tok(i)), x, stat)
         call check(error, stat, 1, 'reject '//trim(tok(i)))
         if (allocated(error)) return
      end do
   end subroutine test_rejected

   subroutine test_nonfinite(error)
      use, intrinsic :: ieee_exceptions, only: ieee_set_halting_mode, ieee_support_halting, ieee_overflow, &
                                               ieee_set_flag
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: x
      integer :: stat
      ! '1e400' overflows in strtod: not a stop in a build that traps overflow (as the deck
      ! reader, which calls the parser, sets it)
      if (ieee_support_halting(ieee_overflow)) call ieee_set_halting_mode(ieee_overflow, .false.)
      call parse_real('NaN', x, stat)
      call check(error, stat, 2, 'NaN')
      if (allocated(error)) return
      call parse_real('-nan', x, stat)
      call check(error, stat, 2, '-nan')
      if (allocated(error)) return
      call parse_real('Infinity', x, stat)
      call check(error, stat, 3, 'Infinity')
      if (allocated(error)) return
      call parse_real('1e400', x, stat)
      call ieee_set_flag(ieee_overflow, .false.)   ! handled
      call check(error, stat, 3, 'overflow')
   end subroutine test_nonfinite

   subroutine test_units(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: f
      logical :: ok
      call units_factor('g', .false., f, ok)
      call check(error, ok .and. f == standard_gravity .and. f == 9.80665_dp, 'g')
      if (allocated(error)) return
      call units_factor('cm/s2', .false., f, ok)
      call check(error, ok .and. f == 0.01_dp, 'cm/s2')
      if (allocated(error)) return
      call units_factor('cm', .true., f, ok)
      call check(error, ok .and. f == 0.01_dp, 'cm')
      if (allocated(error)) return
      call units_factor('g', .true., f, ok)
      call check(error, .not. ok, 'g is not a displacement unit')
      if (allocated(error)) return
      call units_factor('m', .false., f, ok)
      call check(error, .not. ok, 'm is not an acceleration unit')
   end subroutine test_units

end module test_fd_record_parse
