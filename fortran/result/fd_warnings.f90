!> The warnings a run's result calls for, worded once: the executable prints each on standard
!> error after "frictiondyn: warning: ", the summary holds them (key `warnings`), and Python
!> issues them as FrictiondynWarning from the summary. A warning says that the run finished
!> but that its answer needs care: correctness violations left in accepted steps (eqs. 9,
!> 12), steps whose speed-dependent mu did not converge, a step dt1 that does not resolve
!> the highest modes, a harmonic table motion's steady state or a record's peak linear
!> response, a sticking spring's ringing that the step dephases, a velocity-law band's force
!> left alternating, and an energy balance that misses (more than 5 %, or beyond round-off
!> with the average acceleration rule). The figures are those of the summary's keys, which
!> each text names.
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
         s = trim(fmt_int(res%violations))//' step(s) violate the correctness condition (eqs. 9, 12); first at t ='
         do k = 1, res%n_violation_times         ! the first max_violation_times kept
            s = s//' '//trim(fx(res%violation_time(k), 6))
            if (k < res%n_violation_times) s = s//','
         end do
         call push(w, s//' s')
      end if
      if (res%mu_unconverged > 0) then
         call push(w, trim(fmt_int(res%mu_unconverged))//' step(s) could not take a speed-dependent mu at '// &
                  'the velocity at their end, first at t = '//trim(es(res%mu_unconverged_time, 3))// &
                  ' s (mu_unconverged_steps, mu_unconverged_s): the fixed point f0 = P mu(|s''|) of such a '// &
                  'step contracts by about rho = P |dmu/dv| gamma h / m_r a pass and converges within its '// &
                  'passes for rho below about 0.6; here it did not (its last pass still changed a force by '// &
                  trim(es(res%mu_misfit, 3))//' of P mu); those steps hold mu at their start instead, an error of '// &
                  'first order in the step: the mu curve is too steep for the step: raise n1 or lower '// &
                  'dt_min, and keep check_correctness on (such a step is then refined)')
      end if
      if (res%mode_resolution == resolution_unresolved) then
         call push(w, 'dt1 = '//trim(es(res%dt1, 3))//' s does not resolve the highest modes (shortest period '// &
                  trim(es(2*acos(-1.0_dp)/res%omega_max, 3))//' s, omega_max dt1 = '//trim(fx(res%omega_max*res%dt1, 2))// &
                  ' > 2): their response has the wrong period; peak absolute accelerations may carry it '// &
                  '(drifts and shears much less); raise n1 until omega_max dt1 <= 2 to resolve them')
      end if
      if (res%harmonic_resolution == resolution_unresolved) then
         d = maxloc(res%harmonic_error, 1)
         call push(w, 'dt1 = '//trim(es(res%dt1, 3))//' s takes '//trim(fx(1.0_dp/(res%eng%frequency*res%dt1), 2))// &
                  ' steps in a period of the table''s motion: the step alone moves the linear steady-state '// &
                  'amplitude of DOF '//trim(fmt_int(d))//' by '//trim(fx(100*res%harmonic_error(d), 1))// &
                  ' % (harmonic_step_error > 0.05, the stuck or the free system); the response has the '// &
                  'wrong amplitude; raise n1')
      end if
      if (res%record_resolution == resolution_unresolved) then
         d = maxloc(res%record_error, 1)
         call push(w, 'dt1 = '//trim(es(res%dt1, 3))//' s does not resolve the record: the step alone moves the peak '// &
                  'linear response of DOF '//trim(fmt_int(d))//' by '//trim(fx(100*res%record_error(d), 1))// &
                  ' % (record_step_error > 0.05, '//trim(record_system_text(res%record_system))//'); the modes '// &
                  'near the record''s dominant frequencies have the wrong period and the response the '// &
                  'wrong amplitude; raise n1')
      end if
      if (res%stick_resolution == resolution_unresolved) then
         d = maxloc(res%stick_ringing_ratio, 1)
         more = count(res%stick_ringing_ratio > 1.0_dp) - 1
         call push(w, 'the sticking spring of device '//trim(fmt_int(d))//' rings with '// &
                  trim(es(res%stick_ringing(d), 3))//' N against a margin of '//trim(es(res%stick_margin(d), 3))// &
                  ' N to sliding, and dt1 = '//trim(es(res%dt1, 3))//' s puts its frequency '// &
                  trim(fx(100*abs(res%stick_freq_error(d)), 2))//' % off, enough to dephase that ringing within '// &
                  'a stick phase (stick_ringing_ratio = '//trim(fx(res%stick_ringing_ratio(d), 2))//' > 1): its '// &
                  'stick-slip transitions may depend on the step; check with a larger n1 (halving dt1 '// &
                  'quarters that error)'//trim(likewise(more, 'stick_ringing_ratio')))
      end if
      if (res%band_resolution == resolution_unresolved) then
         d = maxloc(res%band_alternation, 1)
         more = count(res%band_alternation > 0.0_dp) - 1
         if (res%band_x(d) > 1.0_dp) then
            s = 'raise n1 until dt1 < '//trim(es(res%dt1/res%band_x(d), 3))//' s (x < 1) or widen eps (exact '// &
                'Coulomb friction, law = ''coulomb'' with technique = ''event_driven'', has no band)'
         else
            s = 'with x <= 1 another mode the step does not resolve drives it (a stiff spring, a hysteretic '// &
                'device''s sticking spring: see mode_resolution and stick_resolution): raise n1'
         end if
         call push(w, 'the force of device '//trim(fmt_int(d))//' alternates from step to step in its velocity '// &
                  'band or at its edge, by +-'//trim(es(res%band_alternation(d), 3))//' N for '// &
                  trim(es(res%band_alternation_time(d), 3))//' s in all (band_alternation_N, band_alternation_s): '// &
                  'Newmark''s rule damps the band''s coupling only where x = (1 - gamma) dt1 (c_i / m_i + '// &
                  'c_j / m_j) < 1 (c_n: the couplings P mu / eps of the velocity-law devices at its node n; '// &
                  '(P mu / eps) dt1 / (2 m_r) for a device alone and average acceleration), and here x = '// &
                  trim(es(res%band_x(d), 3))//'; the device''s force history and the absolute accelerations of its '// &
                  'nodes carry the alternation (with average acceleration, its displacements do not): '//s// &
                  trim(likewise(more, 'band_alternation_N')))
      end if
      if (res%energy_balance == balance_digits) then
         call push(w, 'the energy balance of the average acceleration rule closes at round-off, and this run''s '// &
                  'residual is '//trim(es(abs(res%e_residual_ratio), 1))//' of the energy the structure held and '// &
                  'received (|energy_residual_ratio| > '//trim(es(roundoff_ratio_limit, 1))//'): the integration '// &
                  'lost digits to round-off, typically in a coupling far stiffer than dt1 resolves: a '// &
                  'velocity-law band whose P mu / eps is huge for its masses (x = (P mu / eps) dt1 / (2 m_r) '// &
                  '>> 1, m_r the reduced mass of its two nodes, leaves an alternating force in the band), or a '// &
                  'very stiff spring; its forces and accelerations, and possibly its displacements, carry that '// &
                  'error: widen eps or soften the coupling; a larger n1 helps only once it brings x below 1 '// &
                  '(the alternating force can outlast this warning; band_resolution reports it)')
      else if (res%energy_balance /= balance_closed) then
         if (res%energy_balance == balance_dissipative) then
            s = 'numerical damping (Newmark gamma > 1/2, Moreau-Jean theta > 1/2) the physics does not have; '// &
                'the motion carries it: raise n1 (it shrinks with dt1) or use gamma = theta = 1/2'
         else
            s = 'an energy error of the step (Newmark beta /= 1/4, or a step beyond its rule''s stability '// &
                'limit) the physics does not have; the motion carries it: raise n1 or use beta = 1/4'
         end if
         call push(w, 'the integration '//trim(merge('dissipated', 'created   ', res%e_residual_ratio > 0.0_dp))// &
                  ' '//trim(fx(100*abs(res%e_residual_ratio), 1))//' % of the energy the structure held and '// &
                  'received (|energy_residual_ratio| > '//trim(fx(residual_ratio_limit, 2))//'): '//s)
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
         s = 'the stuck system: no device slid'
      case (record_system_free)
         s = 'the free system: a device slid'
      case (record_system_both)
         s = 'the larger of the stuck and the free system: no device slid, one is velocity-law'
      case default
         s = 'the structure'
      end select
   end function record_system_text

   !> " (n more device(s) likewise: summary key)", or nothing when n = 0.
   pure function likewise(n, key) result(s)
      integer, intent(in) :: n
      character(len=*), intent(in) :: key
      character(len=160) :: s

      s = ''
      if (n > 0) s = ' ('//trim(fmt_int(n))//' more device(s) likewise: summary '//key//')'
   end function likewise

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
