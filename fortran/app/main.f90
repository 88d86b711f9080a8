!> frictiondyn DECK.nml: run one namelist deck and write its time history and summary.
program frictiondyn_main
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use, intrinsic :: iso_c_binding, only: c_int
   use frictiondyn, only: error_type, run_config, result_type, run_deck, output_paths
   implicit none
   type(run_config) :: cfg
   type(result_type) :: res
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

   call run_deck(path, cfg, res, error)
   if (allocated(error)) then
      write (error_unit, '(a)') 'frictiondyn: error: '//error%message
      call quit(1)
   end if

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
contains

   !> End the program with a non-zero exit status, silently, after flushing the output.
   subroutine quit(status)
      integer, intent(in) :: status  !! exit status
      flush (output_unit)
      flush (error_unit)
      call c_exit(int(status, c_int))
   end subroutine quit

end program frictiondyn_main
