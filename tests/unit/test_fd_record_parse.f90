!> Unit tests of the strict number parser of the record reader (fd_record): decimal
!> numbers are read exactly as the compiler reads them; Fortran list-directed tokens,
!> NaN, infinities and malformed numbers are rejected.
module test_fd_record_parse
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_record, only: parse_real, units_factor, standard_gravity, npts_dt, field_width, misplaced_field
   use fd_error, only: fd_error_type => error_type
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
                  new_unittest("units", test_units), &
                  new_unittest("AT2 line 4: tabs, duplicates, extra words", test_line4), &
                  new_unittest("AT2 body: fixed-width fields", test_fields) &
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
      ! the rest of record_units_list: displacements first
      character(len=5), parameter :: known(6) = [character(len=5) :: 'm', 'mm', 'cm', 'gal', 'mm/s2', 'm/s2']
      real(dp), parameter :: factor(6) = [1.0_dp, 1.0e-3_dp, 0.01_dp, 0.01_dp, 1.0e-3_dp, 1.0_dp]
      real(dp) :: f
      logical :: ok
      integer :: k
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
      if (allocated(error)) return
      do k = 1, size(known)
         call units_factor(trim(known(k)), k <= 3, f, ok)
         call check(error, ok .and. f == factor(k), trim(known(k)))
         if (allocated(error)) return
      end do
      call units_factor('cm/s', .false., f, ok)
      call check(error, .not. ok, 'cm/s is no unit of a record')
      if (allocated(error)) return
      call units_factor('m/s2 per', .false., f, ok)
      call check(error, .not. ok, 'a unit is the whole word')
   end subroutine test_units

   !> Line 4 of an AT2 file: the PEER spellings read, tabs as blanks; a key given twice and
   !> a word after NPTS and DT refused, naming the rule.
   subroutine test_line4(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=48), parameter :: good(5) = [character(len=48) :: 'NPTS=  5590, DT=   .0050 SEC', &
                                                 '  5590   .0050   NPTS, DT', 'NPTS, DT: 5590 .0050 SEC', &
                                                 'NPTS='//achar(9)//'5590,'//achar(9)//'DT='//achar(9)//'.0050 SEC', &
                                                 'npts= 5590 dt= .0050']
      character(len=48), parameter :: bad(4) = [character(len=48) :: 'NPTS= 5590, NPTS= 5591, DT= .0050 SEC', &
                                                'NPTS= 5590, DT= .0050, DT= .0060', &
                                                'NPTS= 5590, DT= .0050 SEC  .1412E-01', '5590 .0050 NPTS, DT 3']
      character(len=40), parameter :: rule(4) = [character(len=40) :: 'NPTS is given twice', 'DT is given twice', &
                                                 "'.1412E-01' after NPTS and DT", "'3' after NPTS and DT"]
      type(fd_error_type), allocatable :: err
      integer :: i, npts
      real(dp) :: dt
      do i = 1, size(good)
         call npts_dt('r.AT2', trim(good(i)), npts, dt, err)
         call check(error, .not. allocated(err), 'read: '//trim(good(i)))
         if (allocated(error)) return
         call check(error, npts == 5590 .and. dt == 0.005_dp, 'values of: '//trim(good(i)))
         if (allocated(error)) return
      end do
      do i = 1, size(bad)
         call npts_dt('r.AT2', trim(bad(i)), npts, dt, err)
         call check(error, allocated(err), 'refused: '//trim(bad(i)))
         if (allocated(error)) return
         call check(error, index(err%message, "'r.AT2', line 4: "//trim(rule(i))) > 0, err%message)
         if (allocated(error)) return
      end do
   end subroutine test_line4

   !> The fields of a PEER body line (5E15.7, 5E14.7 without the leading zero), none in a
   !> free-format line; a value cut short, or spilling over its field, found.
   subroutine test_fields(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: e15 = '  1.0000000E-01 -2.0000000E-01  3.0000000E-01'
      character(len=*), parameter :: e14 = '  .1187585E-02 -.1181436E-02  .1177437E-02'
      integer :: lo, hi
      call check(error, field_width(e15), 15, 'E15.7')
      if (allocated(error)) return
      call check(error, field_width(e14//'   '//achar(13)), 14, 'E14.7, trailing blanks and CR')
      if (allocated(error)) return
      call check(error, field_width('0.1 -0.25 0.003'), 0, 'free format')
      if (allocated(error)) return
      call check(error, field_width('-0.12345 0.12345'), 0, 'free format, evenly spaced by chance')
      if (allocated(error)) return
      call check(error, field_width('  1.0000000E-01  2.0000000E-01  3.0000000'), 15, 'the last value cut')
      if (allocated(error)) return
      call check(error, field_width('  1.0000000E-01  2.0000000E-01  3.0000000  4.0'), 0, 'an inner value off')
      if (allocated(error)) return
      call check(error, field_width('  1.0000000E-01  2.0000000'), 0, 'two values, the second off')
      if (allocated(error)) return
      call check(error, field_width('  1.0000000E-01'), 0, 'one value: no layout')
      if (allocated(error)) return
      call check(error, field_width('  1.0E-01,  2.0E-01'), 0, 'a comma: no layout')
      if (allocated(error)) return
      call misplaced_field(e15(1:30), 15, lo, hi)
      call check(error, lo == 0 .and. hi == 0, 'a shorter last line is fine')
      if (allocated(error)) return
      call misplaced_field('  1.0000000E-01  1.4126416', 15, lo, hi)
      call check(error, lo == 18 .and. hi == 26, 'a number cut before its exponent')
      if (allocated(error)) return
      call misplaced_field('  1.0000000E-01  1.4126416E-0', 15, lo, hi)
      call check(error, lo == 18 .and. hi == 29, 'a number cut inside its exponent')
      if (allocated(error)) return
      call misplaced_field('  1.0000000E-0112.0000000E-01', 15, lo, hi)
      call check(error, lo == 3 .and. hi == 29, 'two numbers glued')
   end subroutine test_fields

end module test_fd_record_parse
