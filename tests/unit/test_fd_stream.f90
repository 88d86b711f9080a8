!> Unit tests of the history stream (fd_history_stream, fd_stream_c.c): a row formatted
!> without the heap is byte for byte what gfortran's ES24.16E3 writes (ordinary, tiny, huge,
!> subnormal, negative zero, infinities, NaN), and reads back to the same doubles; a stream
!> written, closed and committed gives the header and the rows; a discarded stream leaves
!> no file.
module test_fd_stream
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf, &
                                            ieee_negative_inf
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_error, only: lib_error => error_type
   use fd_history_stream, only: history_stream, stream_open, stream_row, stream_close, stream_commit, &
                                stream_discard, format_row
   implicit none
   private

   public :: collect_stream

contains

   subroutine collect_stream(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("rows as gfortran writes them", test_format), &
                  new_unittest("write, commit, discard", test_file) &
                  ]
   end subroutine collect_stream

   subroutine test_format(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: m = 8
      real(dp) :: x(m), y(m)
      character(len=25*m) :: mine
      character(len=25*m) :: theirs
      integer :: trial, i, ios

      do trial = 1, 4000
         do i = 1, m
            x(i) = value(trial, i)
         end do
         if (trial == 1) then
            x = [0.0_dp, -0.0_dp, 1.0_dp, -1.0_dp, tiny(1.0_dp), huge(1.0_dp), 4.9e-324_dp, -2.2250738585072e-310_dp]
         else if (trial > 3000) then
            x = hard_value(trial - 3000)
         else if (trial == 2) then
            x(1) = ieee_value(x(1), ieee_quiet_nan)
            x(2) = ieee_value(x(2), ieee_positive_inf)
            x(3) = ieee_value(x(3), ieee_negative_inf)
            x(4) = 9.9999999999999999e-1_dp
            x(5) = 1.0e100_dp
            x(6) = -1.0e-100_dp
         end if
         call format_row(x, mine)
         theirs = ''
         write (theirs(1:25*m - 1), '(8(es24.16e3,:,","))') x
         theirs(25*m:25*m) = achar(10)
         if (mine /= theirs) then
            call check(error, .false., "row differs: '"//mine(1:25*m - 1)//"' against '"//theirs(1:25*m - 1)//"'")
            return
         end if
         if (trial > 2) then
            read (mine(1:25*m - 1), *, iostat=ios) y
            call check(error, ios == 0 .and. all(y == x), 'a row does not read back to the same doubles')
            if (allocated(error)) return
         end if
      end do
   contains
      !> Values where the 17-digit rounding is hardest: the doubles next to powers of ten
      !> (and to 10^k (1 - 1e-17), which round up to the next power), and the doubles nearest
      !> to decimals whose 18th significant digit is 5 (halfway between two 17-digit
      !> mantissas, to within an ulp: the fast path must leave them to snprintf), with exponents
      !> over the range of both paths.
      function hard_value(t) result(v)
         integer, intent(in) :: t
         real(dp) :: v(m), p, d
         integer :: k, i
         k = mod(t*37, 580) - 290
         p = 10.0_dp**k
         v(1) = nearest(p, 1.0_dp)
         v(2) = nearest(p, -1.0_dp)
         v(3) = p*(1.0_dp - 1.0e-17_dp)
         v(4) = -nearest(v(3), -1.0_dp)
         do i = 5, m
            ! d: a 17-digit mantissa from a hash, then +1/2 in its last place
            d = 1.0e16_dp + aint(modulo(sin(real(t*29 + i*11, dp))*43758.5453_dp, 1.0_dp)*9.0e16_dp)
            v(i) = (d + 0.5_dp)*10.0_dp**(k - 16)
            if (i == m) v(i) = nearest(v(i), 1.0_dp)
         end do
      end function hard_value
      !> Values over the whole range of exponents, both signs.
      real(dp) function value(t, i)
         integer, intent(in) :: t, i
         real(dp) :: f
         f = modulo(sin(real(t*13 + i*7, dp))*43758.5453_dp, 1.0_dp)
         value = (1.0_dp + f)*10.0_dp**(mod(t*i*31, 600) - 300)
         if (mod(t + i, 2) == 0) value = -value
      end function value
   end subroutine test_format

   subroutine test_file(error)
      type(error_type), allocatable, intent(out) :: error
      type(history_stream) :: st
      type(lib_error), allocatable :: err
      character(len=*), parameter :: tmp = 'test_fd_stream.csv.tmp', final = 'test_fd_stream.csv'
      character(len=200) :: line
      integer :: unit, ios, k
      logical :: exists

      call stream_open(st, tmp, 'a[m],b[s]', 2, err)
      call check(error, .not. allocated(err), 'stream_open failed')
      if (allocated(error)) return
      do k = 1, 100000   ! more than a buffer's worth
         call stream_row(st, [real(k, dp), 0.5_dp*k])
      end do
      call stream_close(st, err)
      call check(error, .not. allocated(err), 'stream_close failed')
      if (allocated(error)) return
      call stream_commit(st, final, err)
      call check(error, .not. allocated(err), 'stream_commit failed')
      if (allocated(error)) return
      inquire (file=tmp, exist=exists)
      call check(error, .not. exists, 'the temporary name is gone after the commit')
      if (allocated(error)) return
      open (newunit=unit, file=final, status='old', action='read')
      read (unit, '(a)') line
      call check(error, trim(line) == 'a[m],b[s]', 'header: '//trim(line))
      if (allocated(error)) then
         close (unit)
         return
      end if
      do k = 1, 99999
         read (unit, '(a)', iostat=ios) line
      end do
      read (unit, '(a)', iostat=ios) line
      close (unit, status='delete')
      call check(error, ios == 0 .and. line(1:49) == ' 1.0000000000000000E+005, 5.0000000000000000E+004', &
                 'last row: '//trim(line))
      if (allocated(error)) return
      ! discarded: nothing left
      call stream_open(st, tmp, 'a[m]', 1, err)
      call check(error, .not. allocated(err), 'stream_open failed')
      if (allocated(error)) return
      call stream_row(st, [1.0_dp])
      call stream_discard(st)
      inquire (file=tmp, exist=exists)
      call check(error, .not. exists, 'a discarded stream leaves no file')
   end subroutine test_file

end module test_fd_stream
