!> The warnings a run's result calls for, worded once: the executable prints each on standard
!> error after "frictiondyn: warning: ", the summary holds them (key `warnings`), and Python
!> issues them as FrictiondynWarning from the summary. A warning says that the run finished
!> but that its answer needs care: correctness violations left in accepted steps (eqs. 9,
!> 12), steps whose speed-dependent mu did not converge, a step dt1 that does not resolve
!> the highest modes, a harmonic table motion's steady state or a record's peak linear
!> response, a sticking spring's ringing that the step dephases, a velocity-law band's force
!> left alternating, and an energy balance that misses (more than 5 %, or beyond round-off
!> with the average acceleration rule). Each is one line: what happened, with the figures of
!> the summary key it names, what to change, and the section of docs/warnings.md that
!> explains it.
module fd_warnings
   use fd_kinds, only: dp
   use fd_error, only: fmt_int
   use fd_result, only: result_type, resolution_unresolved, residual_ratio_limit, roundoff_ratio_limit, &
                        balance_closed, balance_digits, balance_dissipative, record_system_stuck, &
                        record_system_free, record_system_both
   implicit none
   private

   public :: warning_text, run_warnings

   !> One warning's text, without the executable's "frictiondyn: warning: ".
   type :: warning_text
      character(len=:), allocatable :: text
   end type warning_text

contains

   !> Every warning the result calls for, in the order above (none: an empty array).
   pure subroutine run_warnings(res, w)
      type(result_type), intent(in) :: res                 !! the run's result
      type(warning_text), allocatable, intent(out) :: w(:) !! its warnings
      character(len=:), allocatable :: s
      integer :: d, k, more

      allocate (w(0))
      if (res%violations > 0) then
         s = trim(fmt_int(res%violations))//' step(s) violate the correctness condition (eqs. 9, 12), first at t ='
         do k = 1, min(3, res%n_violation_times)   ! the first three; the summary keeps more
            s = s//' '//trim(fx(res%violation_time(k), 6))
            if (k < min(3, res%n_violation_times)) s = s//','
         end do
         if (res%n_violation_times > 3) s = s//', ...'
         call push(w, s//' s (correctness_violations): lower dt_min or widen eps, eps1'//trim(see('correctness')))
      end if
      if (res%mu_unconverged > 0) then
         call push(w, trim(fmt_int(res%mu_unconverged))//' step(s) could not take a speed-dependent mu at their '// &
                  'end velocity, first at t = '//trim(es(res%mu_unconverged_time, 3))//' s (mu_unconverged_'// &
                  'steps, last change '//trim(es(res%mu_misfit, 3))//' of P mu): raise n1 or lower dt_min'// &
                  trim(see('mu-unconverged')))
      end if
      if (res%mode_resolution == resolution_unresolved) then
         call push(w, 'dt1 = '//trim(es(res%dt1, 3))//' s does not resolve the highest modes (shortest period '// &
                  trim(es(2*acos(-1.0_dp)/res%omega_max, 3))//' s, omega_max_dt1 = '// &
                  trim(fx(res%omega_max*res%dt1, 2))//' > 2): peak accelerations may be off; raise n1'// &
                  trim(see('mode-resolution')))
      end if
      if (res%harmonic_resolution == resolution_unresolved) then
         d = maxloc(res%harmonic_error, 1)
         call push(w, 'dt1 = '//trim(es(res%dt1, 3))//' s takes '//trim(fx(1.0_dp/(res%eng%frequency*res%dt1), 2))// &
                  ' steps a table period: the step alone moves the linear steady-state amplitude of DOF '// &
                  trim(fmt_int(d))//' by '//trim(fx(100*res%harmonic_error(d), 1))//' % (harmonic_step_error > 0.05); '// &
                  'raise n1'//trim(see('harmonic-resolution')))
      end if
      if (res%record_resolution == resolution_unresolved) then
         d = maxloc(res%record_error, 1)
         call push(w, 'dt1 = '//trim(es(res%dt1, 3))//' s does not resolve the record: the step alone moves the peak '// &
                  'linear response of DOF '//trim(fmt_int(d))//' by '//trim(fx(100*res%record_error(d), 1))// &
                  ' % (record_step_error > 0.05, '//trim(record_system_text(res%record_system))//'); raise n1'// &
                  trim(see('record-resolution')))
      end if
      if (res%stick_resolution == resolution_unresolved) then
         d = maxloc(res%stick_ringing_ratio, 1)
         more = count(res%stick_ringing_ratio > 1.0_dp) - 1
         call push(w, 'the sticking spring of device '//trim(fmt_int(d))//' rings with '// &
                  trim(es(res%stick_ringing(d), 3))//' N against a margin of '//trim(es(res%stick_margin(d), 3))// &
                  ' N, dephased by dt1 (stick_ringing_ratio = '//trim(fx(res%stick_ringing_ratio(d), 2))//' > 1'// &
                  trim(likewise(more))//'): raise n1'//trim(see('stick-ringing')))
      end if
      if (res%band_resolution == resolution_unresolved) then
         d = maxloc(res%band_alternation, 1)
         more = count(res%band_alternation > 0.0_dp) - 1
         if (res%band_x(d) > 1.0_dp) then
            s = 'raise n1 until dt1 < '//trim(es(res%dt1/res%band_x(d), 3))//' s or widen eps'
         else
            s = 'another mode the step does not resolve drives it; raise n1'
         end if
         call push(w, 'the force of device '//trim(fmt_int(d))//' alternates step to step in its band '// &
                  '(band_alternation_N = +-'//trim(es(res%band_alternation(d), 3))//' N, x = '// &
                  trim(es(res%band_x(d), 3))//trim(likewise(more))//'): '//s//trim(see('band-alternation')))
      end if
      if (res%energy_balance == balance_digits) then
         call push(w, 'the integration lost digits to round-off (|energy_residual_ratio| = '// &
                  trim(es(abs(res%e_residual_ratio), 1))//' > '//trim(es(roundoff_ratio_limit, 1))// &
                  '): a coupling too stiff for dt1; widen eps or soften it'//trim(see('energy-round-off')))
      else if (res%energy_balance /= balance_closed) then
         if (res%energy_balance == balance_dissipative) then
            s = 'numerical damping (gamma or theta > 1/2); raise n1 or use gamma = theta = 1/2'
         else
            s = 'an energy error of the step (Newmark beta /= 1/4 or unstable); raise n1 or use beta = 1/4'
         end if
         call push(w, 'the integration '//trim(merge('dissipated', 'created   ', res%e_residual_ratio > 0.0_dp))// &
                  ' '//trim(fx(100*abs(res%e_residual_ratio), 1))//' % of the energy (|energy_residual_ratio| > '// &
                  trim(fx(residual_ratio_limit, 2))//'): '//s//trim(see('energy-balance')))
      end if
   end subroutine run_warnings

   !> One more warning. (The texts move to the longer array: gfortran 12's w = [w, x] on a
   !> type with an allocatable component leaks the old array, which LeakSanitizer reports.)
   pure subroutine push(w, text)
      type(warning_text), allocatable, intent(inout) :: w(:)
      character(len=*), intent(in) :: text
      type(warning_text), allocatable :: longer(:)
      integer :: k

      allocate (longer(size(w) + 1))
      do k = 1, size(w)
         call move_alloc(w(k)%text, longer(k)%text)
      end do
      longer(size(w) + 1)%text = text
      call move_alloc(longer, w)
   end subroutine push

   ! The helpers below return fixed-length text, trimmed where it is used: a function with a
   ! character(len=:), allocatable result keeps its length in a static variable of the caller
   ! under gfortran 12, which mixed up texts when runs went side by side in threads (README,
   ! "Rules for the Fortran library"; test_many_concurrent_runs_of_the_same_files_are_identical).

   !> Which system record_step_error judged, in words.
   pure function record_system_text(system) result(s)
      integer, intent(in) :: system
      character(len=96) :: s

      select case (system)
      case (record_system_stuck)
         s = 'stuck system'
      case (record_system_free)
         s = 'free system'
      case (record_system_both)
         s = 'stuck and free'
      case default
         s = 'structure'
      end select
   end function record_system_text

   !> ", n more device(s)" when n > 0, or nothing.
   pure function likewise(n) result(s)
      integer, intent(in) :: n
      character(len=40) :: s

      s = ''
      if (n > 0) s = ', '//trim(fmt_int(n))//' more device(s)'
   end function likewise

   !> The pointer to a warning's explanation: "; see docs/warnings.md#<anchor>".
   pure function see(anchor) result(s)
      character(len=*), intent(in) :: anchor
      character(len=64) :: s

      s = '; see docs/warnings.md#'//anchor
   end function see

   !> x in scientific notation with d digits after the point (1.234E-03), left-adjusted; a
   !> three-digit exponent without its E (1.000+300), as Fortran writes it; NaN, Infinity.
   pure function es(x, d) result(s)
      real(dp), intent(in) :: x
      integer, intent(in) :: d
      character(len=40) :: s
      character(len=40) :: buf, fmt
      integer :: ios

      write (fmt, '(a,i0,a,i0,a)') '(es', d + 8, '.', d, ')'
      write (buf, fmt, iostat=ios) x
      if (ios /= 0) buf = '?'
      s = adjustl(buf)
   end function es

   !> x with d digits after the point, a zero before it (0.05, -0.5), left-adjusted; from
   !> 1e6 on (a run that blows up: an energy ratio of 1e40), or not finite, as es gives it.
   pure function fx(x, d) result(s)
      use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
      real(dp), intent(in) :: x
      integer, intent(in) :: d
      character(len=40) :: s
      character(len=40) :: buf, fmt
      integer :: ios

      if (.not. ieee_is_finite(x) .or. abs(x) >= 1.0e6_dp) then
         s = es(x, d)
         return
      end if
      write (fmt, '(a,i0,a)') '(f0.', d, ')'
      write (buf, fmt, iostat=ios) x
      if (ios /= 0) buf = '?'
      s = adjustl(buf)
      if (s(1:1) == '.') then
         s = '0'//s
      else if (s(1:2) == '-.') then
         s = '-0'//s(2:)
      end if
   end function fx

end module fd_warnings
