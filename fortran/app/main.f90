!> frictiondyn DECK.nml: run one namelist deck and write its time history and summary.
!> The history is written as the run goes (to a temporary name, renamed when the run is
!> complete: memory does not grow with the duration); on a terminal a progress line is shown.
program frictiondyn_main
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use, intrinsic :: iso_c_binding, only: c_int
   use fd_kinds, only: dp
   use frictiondyn, only: error_type, output_paths
   use fd_session, only: session_type, session_open, session_stream, session_solve, session_write, &
                         session_set_progress
   use fd_progress_line, only: progress_wanted, progress_show, progress_clear
   implicit none
   type(session_type), target :: ses
   type(error_type), allocatable :: error
   character(len=:), allocatable :: path, hist, summ
   integer :: nargs, length, i
   interface
      !> C's exit: ends the program with a status and no message (Fortran 2008 has no
      !> silent STOP with a code; STOP's QUIET= is Fortran 2018).
      subroutine c_exit(status) bind(c, name='exit')
         import :: c_int
         integer(c_int), value :: status
      end subroutine c_exit
   end interface

   nargs = command_argument_count()
   if (nargs /= 1) then
      write (error_unit, '(a)') 'usage: frictiondyn DECK.nml'
      write (error_unit, '(a)') '  runs one namelist deck; see docs/namelist.md'
      call quit(2)
   end if
   call get_command_argument(1, length=length)
   allocate (character(len=length) :: path)
   call get_command_argument(1, path)
   if (path == '-h' .or. path == '--help') then
      write (output_unit, '(a)') 'usage: frictiondyn DECK.nml'
      write (output_unit, '(a)') '  runs one namelist deck; see docs/namelist.md'
      stop
   end if

   call session_open(ses, path, error)
   if (.not. allocated(error)) then
      if (progress_wanted()) call session_set_progress(ses, progress_show, 0.2_dp)
      call session_stream(ses, error)
   end if
   if (.not. allocated(error)) then
      call session_solve(ses, error)
      call progress_clear()
      if (allocated(error)) error%message = path//": "//error%message
   end if
   if (.not. allocated(error)) call session_write(ses, error)
   if (allocated(error)) then
      write (error_unit, '(a)') 'frictiondyn: error: '//error%message
      call quit(1)
   end if

   associate (res => ses%res, cfg => ses%cfg)
   if (res%violations > 0) then
      write (error_unit, '(a,i0,a)') 'frictiondyn: warning: ', res%violations, &
         ' step(s) violate the correctness condition (eqs. 9, 12); first at t [s] ='
      write (error_unit, '(10(1x,f0.6))') res%violation_time(1:res%n_violation_times)
   end if
   write (output_unit, '(a)') 'frictiondyn: '//path
   write (output_unit, '(a,f0.6,a,i0,a,i0,a,i0,a)') '  stuck period ', res%period_stuck, ' s; steps dt1 ', &
      res%steps_dt1, ', dt2 ', res%steps_dt2, ', finer ', res%steps_finer, ''
   do i = 1, res%n_devices
      write (output_unit, '(a,i0,a,i0,a,i0)') '  device ', i, ': stick->slip ', res%stick_to_slip(i), &
         ', slip->stick ', res%slip_to_stick(i)
   end do
   do i = 1, res%n_dof
      write (output_unit, '(a,i0,a,es12.5,a,es12.5,a)') '  dof ', i, ': peak |u| ', res%peak_u(i), &
         ' m, peak |a_abs| ', res%peak_aabs(i), ' m/s2'
   end do
   write (output_unit, '(a,i0)') '  correctness violations: ', res%violations
   call output_paths(cfg%out, hist, summ)
   if (cfg%out%history) write (output_unit, '(a)') '  history: '//hist
   write (output_unit, '(a)') '  summary: '//summ
   end associate
contains

   !> End the program with a non-zero exit status, silently, after flushing the output.
   subroutine quit(status)
      integer, intent(in) :: status  !! exit status
      flush (output_unit)
      flush (error_unit)
      call c_exit(int(status, c_int))
   end subroutine quit

end program frictiondyn_main
