!> Unit tests of the record reader (fd_record): one and two columns, comments, the scale,
!> the time-grid check of two-column records, displacement records turned into accelerations
!> (second differences, exact for polynomials up to degree 3, one-sided at the ends), and
!> the messages for bad files. The records are written to the working directory and removed.
module test_fd_record
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_record, only: read_record, record_info
   use test_fd_helpers, only: check_close
   implicit none
   private

   public :: collect_record

   character(len=*), parameter :: file = 'unit_test_fd_record.txt'

contains

   subroutine collect_record(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("one column", test_one_column), &
                  new_unittest("two columns", test_two_columns), &
                  new_unittest("time grid check", test_grid), &
                  new_unittest("displacement: quadratic", test_quadratic), &
                  new_unittest("displacement: cubic", test_cubic), &
                  new_unittest("bad values", test_bad_values), &
                  new_unittest("too few samples", test_too_few), &
                  new_unittest("missing file", test_missing) &
                  ]
   end subroutine collect_record

   !> Write lines to the test file.
   subroutine write_file(lines)
      character(len=*), intent(in) :: lines(:)
      integer :: u, i

      open (newunit=u, file=file, status='replace', action='write')
      do i = 1, size(lines)
         write (u, '(a)') trim(lines(i))
      end do
      close (u)
   end subroutine write_file

   !> Write values (with times t0 + k dt when two_columns) with 17 significant digits.
   subroutine write_values(x, two_columns, t0, dt)
      real(dp), intent(in) :: x(:)
      logical, intent(in) :: two_columns
      real(dp), intent(in) :: t0, dt
      integer :: u, k

      open (newunit=u, file=file, status='replace', action='write')
      do k = 1, size(x)
         if (two_columns) then
            write (u, '(es25.17e3, 1x, es25.17e3)') t0 + (k - 1)*dt, x(k)
         else
            write (u, '(es25.17e3)') x(k)
         end if
      end do
      close (u)
   end subroutine write_values

   subroutine remove_file()
      integer :: u
      open (newunit=u, file=file, status='old')
      close (u, status='delete')
   end subroutine remove_file

   !> Comments ('#', '!') and blank lines skipped; every value times the scale.
   subroutine test_one_column(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: acc(:)
      type(record_info) :: info
      type(fd_error_type), allocatable :: err

      call write_file([character(len=20) :: '# table acceleration', '0.0', '', '  0.25', '! a note', '-1.5e-2', '3'])
      call read_record(file, 'auto', .false., '', 2.0_dp, 0.01_dp, acc, info, err)
      call remove_file()
      call check(error, .not. allocated(err), 'a good record')
      if (allocated(error)) return
      call check(error, size(acc), 4, 'four samples')
      if (allocated(error)) return
      call check(error, all(acc == [0.0_dp, 0.5_dp, -3.0e-2_dp, 6.0_dp]), 'values times the scale 2')
   end subroutine test_one_column

   !> Time and value, separated by blanks, a comma or a tab; the grid may start anywhere.
   subroutine test_two_columns(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: acc(:)
      type(record_info) :: info
      type(fd_error_type), allocatable :: err

      call write_file([character(len=30) :: '0.50 1.0', '0.51, -2.0', '0.52'//achar(9)//'4.0', &
                       '0.5300000001 8.0'])
      call read_record(file, 'auto', .false., '', 1.0_dp, 0.01_dp, acc, info, err)
      call remove_file()
      call check(error, .not. allocated(err), 'a good two-column record (times within 1e-6 dt of the grid)')
      if (allocated(error)) return
      call check(error, size(acc) == 4 .and. all(acc == [1.0_dp, -2.0_dp, 4.0_dp, 8.0_dp]), 'the second column')
   end subroutine test_two_columns

   !> A time off the grid of dt_record: an error naming the file, the line and the time.
   subroutine test_grid(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: acc(:)
      type(record_info) :: info
      type(fd_error_type), allocatable :: err

      call write_file([character(len=20) :: '# t a', '0.00 0.0', '0.01 0.1', '0.03 0.2'])
      call read_record(file, 'auto', .false., '', 1.0_dp, 0.01_dp, acc, info, err)
      call remove_file()
      call check(error, allocated(err), 'a time off the grid')
      if (allocated(error)) return
      call check(error, index(err%message, "record file '"//file//"', line 4: time 0.03 is not on the grid of "// &
                              "dt_record = 0.01 s starting at 0 s") > 0, err%message)
      if (allocated(error)) return
      ! the same times with dt_record = 0.015 fail at line 3
      call write_file([character(len=20) :: '0.00 0.0', '0.01 0.1', '0.03 0.2'])
      call read_record(file, 'auto', .false., '', 1.0_dp, 0.015_dp, acc, info, err)
      call remove_file()
      call check(error, allocated(err), 'a time off the grid')
      if (allocated(error)) return
      call check(error, index(err%message, 'line 2: time 0.01') > 0, err%message)
      if (allocated(error)) return
      ! 1e-4 dt off the grid is too much (the reader allows 1e-6 dt for rounded times)
      call write_file([character(len=20) :: '0.00 0.0', '0.01 0.1', '0.020001 0.2'])
      call read_record(file, 'auto', .false., '', 1.0_dp, 0.01_dp, acc, info, err)
      call remove_file()
      call check(error, allocated(err), 'a time 1e-4 dt off the grid')
      if (allocated(error)) return
      call check(error, index(err%message, 'line 3: time 0.020001') > 0, err%message)
   end subroutine test_grid

   !> x = x0 + b t + c t^2: every second difference is 2 c, the one-sided ones at the ends too
   !> (to round-off: the values, 17 digits, divided by dt^2 = 1e-4; measured 8e-13).
   subroutine test_quadratic(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: acc(:)
      type(record_info) :: info
      real(dp) :: x(51)
      type(fd_error_type), allocatable :: err
      real(dp), parameter :: dt = 0.01_dp, c = 0.75_dp
      integer :: k

      x = [(3.0e-3_dp - 0.02_dp*(k*dt) + c*(k*dt)**2, k=0, 50)]
      call write_values(x, .false., 0.0_dp, dt)
      call read_record(file, 'auto', .true., '', 1.0_dp, dt, acc, info, err)
      call remove_file()
      call check(error, .not. allocated(err) .and. size(acc) == size(x), 'a displacement record')
      if (allocated(error)) return
      do k = 1, size(acc)
         call check_close(error, acc(k), 2.0_dp*c, 1.0e-11_dp, 'second difference of a quadratic')
         if (allocated(error)) return
      end do
   end subroutine test_quadratic

   !> x = d t^3 (two columns, scaled by 1/2): a(t) = 3 d t at every sample, the ends included.
   subroutine test_cubic(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: acc(:)
      type(record_info) :: info
      real(dp) :: x(31)
      type(fd_error_type), allocatable :: err
      real(dp), parameter :: dt = 0.02_dp, d = 0.4_dp
      integer :: k

      x = [(d*(k*dt)**3, k=0, 30)]
      call write_values(x, .true., 0.0_dp, dt)
      call read_record(file, 'auto', .true., '', 0.5_dp, dt, acc, info, err)
      call remove_file()
      call check(error, .not. allocated(err) .and. size(acc) == size(x), 'a displacement record')
      if (allocated(error)) return
      do k = 1, size(acc)
         call check_close(error, acc(k), 3.0_dp*d*((k - 1)*dt), 1.0e-11_dp, &
                          'second difference of a cubic (absolute, m/s2)', absolute=.true.)
         if (allocated(error)) return
      end do
   end subroutine test_cubic

   subroutine test_bad_values(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: acc(:)
      type(record_info) :: info
      type(fd_error_type), allocatable :: err

      call write_file([character(len=20) :: '0.0', '0.1', 'nan', '0.2'])
      call read_record(file, 'auto', .false., '', 1.0_dp, 0.01_dp, acc, info, err)
      call check(error, allocated(err), 'NaN')
      if (allocated(error)) return
      call check(error, index(err%message, "line 3: 'nan' is NaN: not finite") > 0, err%message)
      if (allocated(error)) return
      call write_file([character(len=20) :: '0.0', '0.1x', '0.2'])
      call read_record(file, 'auto', .false., '', 1.0_dp, 0.01_dp, acc, info, err)
      call check(error, allocated(err), 'not a number')
      if (allocated(error)) return
      call check(error, index(err%message, "line 2: '0.1x' is not a number") > 0, err%message)
      if (allocated(error)) return
      call write_file([character(len=20) :: '0.0', '0.1', '0.2 0.3'])
      call read_record(file, 'auto', .false., '', 1.0_dp, 0.01_dp, acc, info, err)
      call check(error, allocated(err), 'a change of the number of columns')
      if (allocated(error)) return
      call check(error, index(err%message, "line 3: expected one column (one value a line), found 2 values") > 0, &
                 err%message)
      if (allocated(error)) return
      call write_file([character(len=20) :: '0.0 1 2', '0.1 1 2'])
      call read_record(file, 'auto', .false., '', 1.0_dp, 0.01_dp, acc, info, err)
      call remove_file()
      call check(error, allocated(err), 'three columns')
      if (allocated(error)) return
      call check(error, index(err%message, "line 1: expected one column (one value a line), found 3 values") > 0, &
                 err%message)
   end subroutine test_bad_values

   !> An acceleration record needs 2 samples, a displacement record 4 (the end formulas).
   subroutine test_too_few(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: acc(:)
      type(record_info) :: info
      type(fd_error_type), allocatable :: err

      call write_file([character(len=20) :: '# one', '0.5'])
      call read_record(file, 'auto', .false., '', 1.0_dp, 0.01_dp, acc, info, err)
      call check(error, allocated(err), 'one sample')
      if (allocated(error)) return
      call check(error, index(err%message, 'has 1 samples; at least 2 are needed') > 0, err%message)
      if (allocated(error)) return
      call write_file([character(len=20) :: '0.0', '0.1', '0.2'])
      call read_record(file, 'auto', .true., '', 1.0_dp, 0.01_dp, acc, info, err)
      call check(error, allocated(err), 'a displacement record of 3 samples')
      if (allocated(error)) return
      call check(error, index(err%message, 'has 3 samples; at least 4 are needed') > 0, err%message)
      if (allocated(error)) return
      call read_record(file, 'auto', .false., '', 1.0_dp, 0.01_dp, acc, info, err)
      call remove_file()
      call check(error, .not. allocated(err) .and. size(acc) == 3, 'the same 3 samples as accelerations')
   end subroutine test_too_few

   subroutine test_missing(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: acc(:)
      type(record_info) :: info
      type(fd_error_type), allocatable :: err

      call read_record('no_such_record_for_the_unit_tests.txt', 'auto', .false., '', 1.0_dp, 0.01_dp, acc, info, err)
      call check(error, allocated(err), 'a missing file')
      if (allocated(error)) return
      call check(error, err%message, "file 'no_such_record_for_the_unit_tests.txt' does not exist")
   end subroutine test_missing

end module test_fd_record
