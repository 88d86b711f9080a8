!> The executable's progress line: on a terminal, one line on standard error rewritten in
!> place ("\r") with the time reached, the share done and an estimate of the time left;
!> nothing when standard error is not a terminal (a batch job, a pipe). Program code (it
!> prints), not library code: the library only calls the callback (fd_run_control).
module fd_progress_line
   use, intrinsic :: iso_fortran_env, only: error_unit, int64
   use, intrinsic :: iso_c_binding, only: c_int
   use fd_kinds, only: dp
   use fd_fileops, only: c_isatty
   implicit none
   private

   public :: progress_wanted, progress_show, progress_clear

   integer(int64), save :: start = -1   ! clock count at the first report (program state)
   logical, save :: shown = .false.     ! a line is on the screen

contains

   !> Whether standard error is a terminal.
   logical function progress_wanted()
      progress_wanted = c_isatty(2_c_int) == 1
   end function progress_wanted

   !> The progress callback: rewrite the line.
   subroutine progress_show(t, duration)
      real(dp), intent(in) :: t          !! time reached [s]
      real(dp), intent(in) :: duration   !! duration of the run [s]
      integer(int64) :: now, rate
      real(dp) :: elapsed, frac
      character(len=96) :: line

      call system_clock(now, rate)
      if (start < 0) start = now
      elapsed = real(now - start, dp)/real(rate, dp)
      frac = 0.0_dp
      if (duration > 0.0_dp) frac = min(1.0_dp, t/duration)
      if (frac > 0.0_dp .and. elapsed > 0.0_dp) then
         write (line, '(a,f0.2,a,f0.2,a,f5.1,a,i0,a)') 'frictiondyn: t = ', t, ' of ', duration, ' s (', &
            100.0_dp*frac, ' %), about ', nint(elapsed*(1.0_dp - frac)/frac), ' s left'
      else
         write (line, '(a,f0.2,a,f0.2,a)') 'frictiondyn: t = ', t, ' of ', duration, ' s'
      end if
      write (error_unit, '(a)', advance='no') achar(13)//line
      flush (error_unit)
      shown = .true.
   end subroutine progress_show

   !> Remove the line (before other output).
   subroutine progress_clear()
      if (.not. shown) return
      write (error_unit, '(a)', advance='no') achar(13)//repeat(' ', 96)//achar(13)
      flush (error_unit)
      shown = .false.
   end subroutine progress_clear

end module fd_progress_line
