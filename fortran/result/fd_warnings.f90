!> The checks of a run's result, each as a check record (fd_check), and the warnings they
!> call for, worded once: the executable prints each on standard error after "frictiondyn:
!> warning: ", the summary holds them (key `warnings`), and Python issues them as
!> FrictiondynWarning from the summary. A warning says that the run finished but that its
!> answer needs care: correctness violations left in accepted steps (eqs. 9, 12), steps
!> whose speed-dependent mu did not converge, a step dt1 that does not resolve the highest
!> modes, a harmonic table motion's steady state or a record's peak linear response, a
!> sticking spring's ringing that the step dephases, a velocity-law band's force left
!> alternating, an energy balance that misses (more than 5 %, or beyond round-off with
!> the average acceleration rule), and a model or record outside what structures and
!> earthquakes have (a first period beyond 0.01-10 s, a record's peak acceleration beyond
!> 0.005-3 g: most likely a unit typed wrong). Each is one line: what happened, with the figures of the
!> summary key it names, what to change, and the section of docs/warnings.md that explains
!> it. The warnings are a filter over the checks (check_warnings): a new check is one
!> routine here and one line of run_checks.
module fd_warnings
   use fd_kinds, only: dp
   use fd_error, only: fmt_int
   use fd_result, only: result_type, run_setup, setup_of, resolution_none, resolution_resolved, &
                        resolution_unresolved, resolution_names, residual_ratio_limit, roundoff_ratio_limit, &
                        balance_closed, balance_digits, balance_dissipative, energy_balance_of, energy_balance_names, &
                        mode_resolution_limit, harmonic_error_limit, record_error_limit, &
                        record_system_stuck, record_system_free, record_system_both
   use fd_check, only: check_type, warning_text, add_figure, check_warnings, verdict_not_applicable, &
                       verdict_passed, verdict_warns, verdict_names
   implicit none
   private

   public :: warning_text, run_warnings, run_checks, n_checks
   public :: period_shortest, period_longest, pga_smallest, pga_largest, standard_gravity

   !> The checks of a run, in the order of their warnings.
   integer, parameter :: n_checks = 11

   ! what structures and earthquakes have: a first period, a record's peak acceleration
   real(dp), parameter :: period_shortest = 0.01_dp   !! below: implausible [s]
   real(dp), parameter :: period_longest = 10.0_dp    !! above: implausible [s]
   real(dp), parameter :: pga_smallest = 0.005_dp     !! below: implausible [g]
   real(dp), parameter :: pga_largest = 3.0_dp        !! above: implausible [g]
   real(dp), parameter :: standard_gravity = 9.80665_dp !! g [m/s2]

contains

   !> Every warning the result calls for, in the order of the checks (none: an empty array).
   pure subroutine run_warnings(res, w)
      type(result_type), intent(in) :: res                 !! the run's result
      type(warning_text), allocatable, intent(out) :: w(:) !! its warnings
      type(check_type) :: checks(n_checks)

      call run_checks(res, checks)
      call check_warnings(checks, w)
   end subroutine run_warnings

   !> The checks of a result, each judged here from the figures the run left in it:
   !> the correctness condition, a speed-dependent mu, the highest modes, a harmonic table
   !> motion, a record, the sticking springs' ringing, the velocity-law bands, the energy
   !> balance, the first period's and the record's peak acceleration's plausibility, a planar
   !> bearing's uplift.
   pure subroutine run_checks(res, checks)
      type(result_type), intent(in) :: res                 !! the run's result
      type(check_type), intent(out) :: checks(n_checks)    !! its checks

      call correctness_check(res, checks(1))
      call mu_check(res, checks(2))
      call mode_check(res, checks(3))
      call harmonic_check(res, checks(4))
      call record_check(res, checks(5))
      call stick_check(res, checks(6))
      call band_check(res, checks(7))
      call energy_check(res, checks(8))
      call period_check(res, checks(9))
      call record_range_check(res, checks(10))
      call uplift_check(res, checks(11))
   end subroutine run_checks

   !> Whether a planar bearing lifted off (its normal force N <= 0 under a vertical component or the overturning):
   !> while lifted it carries no friction and no restoring force.
   pure subroutine uplift_check(res, c)
      type(result_type), intent(in) :: res   !! the result
      type(check_type), intent(out) :: c     !! the check
      integer :: b, worst

      c%key = 'bearing_uplift'
      if (res%n_bearings == 0) return
      c%verdict = merge(verdict_warns, verdict_passed, any(res%bearing_uplifts > 0))
      c%outcome = verdict_names(c%verdict)
      call add_figure(c, 'bearings_lifted', real(count(res%bearing_uplifts > 0), dp))
      if (c%verdict /= verdict_warns) return
      worst = 1
      do b = 2, res%n_bearings
         if (res%bearing_uplift_time(b) > res%bearing_uplift_time(worst)) worst = b
      end do
      call add_figure(c, 'bearing', real(worst, dp))
      call add_figure(c, 'bearing_uplift_duration_s', res%bearing_uplift_time(worst))
      c%warning = trim(fmt_int(count(res%bearing_uplifts > 0)))//' bearing(s) lifted off (N <= 0: no friction, '// &
                  'no restoring force), bearing '//trim(fmt_int(worst))//' for '// &
                  trim(es(res%bearing_uplift_time(worst), 3))//' s from t = '// &
                  trim(es(res%bearing_uplift_first(worst), 3))//' s (bearing_uplift_*): check the ground '// &
                  'motion and the bearings'//trim(see('bearing-uplift'))
   end subroutine uplift_check

   !> The verdict of a step check and its word in the summary: not applicable when the check
   !> did not apply (`checked` false), else 'unresolved' (warns) when a figure is beyond its
   !> limit (`beyond`), 'resolved' (passed) otherwise.
   pure subroutine resolution_verdict(c, checked, beyond)
      type(check_type), intent(inout) :: c   !! the check
      logical, intent(in) :: checked         !! the check applies (its figures are set)
      logical, intent(in) :: beyond          !! a figure is beyond its limit
      integer :: resolution

      resolution = resolution_none
      c%verdict = verdict_not_applicable
      if (checked) then
         resolution = merge(resolution_unresolved, resolution_resolved, beyond)
         c%verdict = merge(verdict_warns, verdict_passed, beyond)
      end if
      c%outcome = resolution_names(resolution)
   end subroutine resolution_verdict

   !> The correctness condition (eqs. 9, 12): steps accepted that violate it.
   pure subroutine correctness_check(res, c)
      type(result_type), intent(in) :: res   !! the result
      type(check_type), intent(out) :: c     !! the check
      character(len=:), allocatable :: s
      integer :: k

      c%key = 'correctness_violations'
      c%verdict = merge(verdict_warns, verdict_passed, res%violations > 0)
      c%outcome = verdict_names(c%verdict)
      call add_figure(c, 'correctness_violations', real(res%violations, dp))
      do k = 1, min(3, res%n_violation_times)   ! the first three; the summary keeps more
         call add_figure(c, 'violation_times_s('//trim(fmt_int(k))//')', res%violation_time(k))
      end do
      if (c%verdict /= verdict_warns) return
      s = trim(fmt_int(res%violations))//' step(s) violate the correctness condition (eqs. 9, 12), first at t ='
      do k = 1, min(3, res%n_violation_times)
         s = s//' '//trim(fx(res%violation_time(k), 6))
         if (k < min(3, res%n_violation_times)) s = s//','
      end do
      if (res%n_violation_times > 3) s = s//', ...'
      c%warning = s//' s (correctness_violations): lower dt_min or widen eps, eps1'//trim(see('correctness'))
   end subroutine correctness_check

   !> A speed-dependent mu: steps accepted with their sliding forces unconverged.
   pure subroutine mu_check(res, c)
      type(result_type), intent(in) :: res   !! the result
      type(check_type), intent(out) :: c     !! the check

      c%key = 'mu_unconverged_steps'
      c%verdict = merge(verdict_warns, verdict_passed, res%mu_unconverged > 0)
      c%outcome = verdict_names(c%verdict)
      call add_figure(c, 'mu_unconverged_steps', real(res%mu_unconverged, dp))
      if (c%verdict /= verdict_warns) return
      call add_figure(c, 'mu_unconverged_s', res%mu_unconverged_time)
      call add_figure(c, 'mu_unconverged_misfit', res%mu_misfit)
      c%warning = trim(fmt_int(res%mu_unconverged))//' step(s) could not take a speed-dependent mu at their '// &
                  'end velocity, first at t = '//trim(es(res%mu_unconverged_time, 3))//' s (mu_unconverged_'// &
                  'steps, last change '//trim(es(res%mu_misfit, 3))//' of P mu): raise n1 or lower dt_min'// &
                  trim(see('mu-unconverged'))
   end subroutine mu_check

   !> Whether dt1 resolves the highest modes (fd_mode_resolution): omega_max dt1 against
   !> mode_resolution_limit.
   pure subroutine mode_check(res, c)
      type(result_type), intent(in) :: res   !! the result
      type(check_type), intent(out) :: c     !! the check
      real(dp) :: dt1

      dt1 = step_of(res)
      c%key = 'mode_resolution'
      call resolution_verdict(c, res%mode_checked, res%omega_max*dt1 > mode_resolution_limit)
      if (c%verdict == verdict_not_applicable) return
      call add_figure(c, 'dt1_s', dt1)
      call add_figure(c, 'omega_max_dt1', res%omega_max*dt1)
      if (c%verdict /= verdict_warns) return
      c%warning = 'dt1 = '//trim(es(dt1, 3))//' s does not resolve the highest modes (shortest period '// &
                  trim(es(2*acos(-1.0_dp)/res%omega_max, 3))//' s, omega_max_dt1 = '// &
                  trim(fx(res%omega_max*dt1, 2))//' > 2): peak accelerations may be off; raise n1'// &
                  trim(see('mode-resolution'))
   end subroutine mode_check

   !> The main step dt1 of the technique that ran [s] (0: none).
   pure real(dp) function step_of(res) result(dt1)
      type(result_type), intent(in) :: res   !! the result
      type(run_setup) :: setup

      setup = setup_of(res)
      dt1 = setup%dt1
   end function step_of

   !> The head of a check judged by its largest value per DOF or device (harmonic, record,
   !> stick ringing, band alternation): its key, its verdict (when `checked`: 'unresolved'
   !> when a value is above `limit`), and (when it applies) the figures `what` (the DOF or
   !> device of the largest value, d; 0 when the check does not apply) and that value under
   !> the name `name`, then the step dt1 [s] when given (a DOF's step error); with `more`, when
   !> it warns, how many others are above `limit` (the figure more_devices).
   pure subroutine largest_check(c, key, checked, limit, values, what, name, d, dt1, more)
      type(check_type), intent(out) :: c                 !! the check
      character(len=*), intent(in) :: key                !! its key
      logical, intent(in) :: checked                     !! the check applies
      real(dp), intent(in) :: limit                      !! a value above it: unresolved
      real(dp), allocatable, intent(in) :: values(:)     !! per DOF or device (not allocated: none)
      character(len=*), intent(in) :: what               !! 'dof' or 'device'
      character(len=*), intent(in) :: name               !! the values' summary key
      integer, intent(out) :: d                          !! the DOF or device of the largest value
      real(dp), intent(in), optional :: dt1              !! the step judged [s]
      integer, intent(out), optional :: more             !! the others above limit (0 unless it warns)
      logical :: beyond

      d = 0
      if (present(more)) more = 0
      c%key = key
      beyond = .false.
      if (allocated(values)) beyond = any(values > limit)
      call resolution_verdict(c, checked, beyond)
      if (c%verdict == verdict_not_applicable .or. .not. allocated(values)) return
      if (size(values) == 0) return
      d = maxloc(values, 1)
      call add_figure(c, what, real(d, dp))
      call add_figure(c, name, values(d))
      if (present(dt1)) call add_figure(c, 'dt1_s', dt1)
      if (.not. present(more) .or. c%verdict /= verdict_warns) return
      more = count(values > limit) - 1
      call add_figure(c, 'more_devices', real(more, dp))
   end subroutine largest_check

   !> Whether dt1 resolves a harmonic table motion's steady state (fd_harmonic_resolution).
   pure subroutine harmonic_check(res, c)
      type(result_type), intent(in) :: res   !! the result
      type(check_type), intent(out) :: c     !! the check
      real(dp) :: dt1
      integer :: d

      dt1 = step_of(res)
      call largest_check(c, 'harmonic_resolution', res%harmonic_checked, harmonic_error_limit, res%harmonic_error, &
                         'dof', 'harmonic_step_error', d, dt1)
      if (c%verdict /= verdict_warns .or. d == 0) return
      c%warning = 'dt1 = '//trim(es(dt1, 3))//' s takes '//trim(fx(1.0_dp/(res%eng%frequency*dt1), 2))// &
                  ' steps a table period: the step alone moves the linear steady-state amplitude of DOF '// &
                  trim(fmt_int(d))//' by '//trim(fx(100*res%harmonic_error(d), 1))//' % (harmonic_step_error > '// &
                  '0.05); raise n1'//trim(see('harmonic-resolution'))
   end subroutine harmonic_check

   !> Whether dt1 resolves a record's peak linear response (fd_record_resolution).
   pure subroutine record_check(res, c)
      type(result_type), intent(in) :: res   !! the result
      type(check_type), intent(out) :: c     !! the check
      real(dp) :: dt1
      integer :: d

      dt1 = step_of(res)
      call largest_check(c, 'record_resolution', res%record_checked, record_error_limit, res%record_error, 'dof', &
                         'record_step_error', d, dt1)
      if (c%verdict /= verdict_warns .or. d == 0) return
      c%warning = 'dt1 = '//trim(es(dt1, 3))//' s does not resolve the record: the step alone moves the peak '// &
                  'linear response of DOF '//trim(fmt_int(d))//' by '//trim(fx(100*res%record_error(d), 1))// &
                  ' % (record_step_error > 0.05, '//trim(record_system_text(res%record_system))//'); raise n1'// &
                  trim(see('record-resolution'))
   end subroutine record_check

   !> Whether dt1 resolves the sticking springs' ringing (fd_stick_ringing).
   pure subroutine stick_check(res, c)
      type(result_type), intent(in) :: res   !! the result
      type(check_type), intent(out) :: c     !! the check
      integer :: d, more

      call largest_check(c, 'stick_resolution', res%stick_checked, 1.0_dp, res%stick_ringing_ratio, 'device', &
                         'stick_ringing_ratio', d, more=more)
      if (c%verdict /= verdict_warns .or. d == 0) return
      call add_figure(c, 'stick_ringing_N', res%stick_ringing(d))
      call add_figure(c, 'stick_margin_N', res%stick_margin(d))
      c%warning = 'the sticking spring of device '//trim(fmt_int(d))//' rings with '// &
                  trim(es(res%stick_ringing(d), 3))//' N against a margin of '//trim(es(res%stick_margin(d), 3))// &
                  ' N, dephased by dt1 (stick_ringing_ratio = '//trim(fx(res%stick_ringing_ratio(d), 2))//' > 1'// &
                  trim(likewise(more))//'): raise n1'//trim(see('stick-ringing'))
   end subroutine stick_check

   !> Whether the step damps the velocity-law bands (fd_band_alternation).
   pure subroutine band_check(res, c)
      type(result_type), intent(in) :: res   !! the result
      type(check_type), intent(out) :: c     !! the check
      character(len=:), allocatable :: s
      integer :: d, more

      call largest_check(c, 'band_resolution', res%band_checked, 0.0_dp, res%band_alternation, 'device', &
                         'band_alternation_N', d, more=more)
      if (c%verdict /= verdict_warns .or. d == 0) return
      call add_figure(c, 'band_x', res%band_x(d))
      if (res%band_x(d) > 1.0_dp) then
         s = 'raise n1 until dt1 < '//trim(es(step_of(res)/res%band_x(d), 3))//' s or widen eps'
      else
         s = 'another mode the step does not resolve drives it; raise n1'
      end if
      c%warning = 'the force of device '//trim(fmt_int(d))//' alternates step to step in its band '// &
                  '(band_alternation_N = +-'//trim(es(res%band_alternation(d), 3))//' N, x = '// &
                  trim(es(res%band_x(d), 3))//trim(likewise(more))//'): '//s//trim(see('band-alternation'))
   end subroutine band_check

   !> Whether the energy balance closes (energy_balance_of, with what the technique's rule
   !> means for it: run_setup): round-off beyond roundoff_ratio_limit, or a residual beyond
   !> residual_ratio_limit, warns.
   pure subroutine energy_check(res, c)
      type(result_type), intent(in) :: res   !! the result
      type(check_type), intent(out) :: c     !! the check
      character(len=:), allocatable :: s
      type(run_setup) :: setup
      integer :: balance

      setup = setup_of(res)
      balance = energy_balance_of(res%e_residual_ratio, setup%damping_method, setup%exact_accounting)
      c%key = 'energy_balance'
      c%verdict = merge(verdict_passed, verdict_warns, balance == balance_closed)
      c%outcome = energy_balance_names(balance)
      call add_figure(c, 'energy_residual_ratio', res%e_residual_ratio)
      if (balance == balance_digits) then
         c%warning = 'the integration lost digits to round-off (|energy_residual_ratio| = '// &
                     trim(es(abs(res%e_residual_ratio), 1))//' > '//trim(es(roundoff_ratio_limit, 1))// &
                     '): a coupling too stiff for dt1; widen eps or soften it'//trim(see('energy-round-off'))
      else if (balance /= balance_closed) then
         if (balance == balance_dissipative) then
            s = 'numerical damping (gamma or theta > 1/2); raise n1 or use gamma = theta = 1/2'
         else
            s = 'an energy error of the step (Newmark beta /= 1/4 or unstable); raise n1 or use beta = 1/4'
         end if
         c%warning = 'the integration '//trim(merge('dissipated', 'created   ', res%e_residual_ratio > 0.0_dp))// &
                     ' '//trim(fx(100*abs(res%e_residual_ratio), 1))//' % of the energy (|energy_residual_ratio| > '// &
                     trim(fx(residual_ratio_limit, 2))//'): '//s//trim(see('energy-balance'))
      end if
   end subroutine energy_check

   !> The structure's first period T1 [s] and its summary key: the stuck system's
   !> (period_stuck_s) or, where it has none (every mass held to the table through its
   !> devices), the free system's first finite one (periods_free_s); 0 and blank when neither.
   pure subroutine first_period(res, t1, key)
      type(result_type), intent(in) :: res   !! the result
      real(dp), intent(out) :: t1            !! T1 [s] (0: none)
      character(len=*), intent(out) :: key   !! its summary key
      type(run_setup) :: setup
      integer :: k

      t1 = 0.0_dp
      key = ''
      setup = setup_of(res)
      if (setup%period_stuck > 0.0_dp) then
         t1 = setup%period_stuck
         key = 'period_stuck_s'
         return
      end if
      if (.not. allocated(res%eng%free%omega2)) return
      do k = 1, min(res%eng%free%n, size(res%eng%free%omega2))
         if (.not. (res%eng%free%omega2(k) > 0.0_dp)) cycle
         t1 = res%eng%free%period(k)
         key = 'periods_free_s('//trim(fmt_int(k))//')'
         return
      end do
   end subroutine first_period

   !> Whether the first period lies where structures have theirs, 0.01 s to 10 s: beyond, a
   !> unit typed wrong is the likely cause (a stiffness in kN/m typed as N/m makes T1 31.6
   !> times too long, masses in t typed as kg 31.6 times too short).
   pure subroutine period_check(res, c)
      type(result_type), intent(in) :: res   !! the result
      type(check_type), intent(out) :: c     !! the check
      character(len=24) :: key
      real(dp) :: t1

      c%key = 'period_plausibility'
      call first_period(res, t1, key)
      if (.not. (t1 > 0.0_dp)) return
      call add_figure(c, trim(key), t1)
      call plausible(c, t1 > period_longest .or. t1 < period_shortest)
      if (t1 > period_longest) then
         c%warning = 'the first period T1 = '//trim(fx(t1, 1))//' s ('//trim(key)//') is beyond 10 s, '// &
                     'longer than structures have: a stiffness in kN/m typed as N/m?'//trim(see('implausible-period'))
      else if (t1 < period_shortest) then
         c%warning = 'the first period T1 = '//trim(es(t1, 2))//' s ('//trim(key)//') is below 0.01 s, '// &
                     'shorter than structures have: masses in t typed as kg, or a stiffness in N/mm typed as N/m?'// &
                     trim(see('implausible-period'))
      end if
   end subroutine period_check

   !> Whether a record's peak table acceleration lies where earthquakes have theirs, 0.005 g
   !> to 3 g: beyond, a record read in the wrong units is the likely cause (cm/s2 read as g
   !> or m/s2 makes it 981 or 100 times too large; g or m/s2 read as cm/s2 that much too
   !> small). Not applicable without a record, or to a record of zeros (free vibration).
   pure subroutine record_range_check(res, c)
      type(result_type), intent(in) :: res   !! the result
      type(check_type), intent(out) :: c     !! the check
      real(dp) :: pga

      c%key = 'record_plausibility'
      if (.not. (res%record_pga > 0.0_dp)) return
      pga = res%record_pga/standard_gravity
      call add_figure(c, 'record.peak_acc_mps2', res%record_pga)
      call add_figure(c, 'pga_g', pga)
      call plausible(c, pga > pga_largest .or. pga < pga_smallest)
      if (pga > pga_largest) then
         c%warning = 'the record peaks at '//trim(fx(pga, 1))//' g (record.peak_acc_mps2 = '// &
                     trim(es(res%record_pga, 3))//'), beyond 3 g, more than '// &
                     'earthquakes have: a record in cm/s2 read as g or m/s2? set record_units'// &
                     trim(see('implausible-record'))
      else if (pga < pga_smallest) then
         c%warning = 'the record peaks at '//trim(es(pga, 2))//' g (record.peak_acc_mps2 = '// &
                     trim(es(res%record_pga, 3))//'), below 0.005 g, less than '// &
                     'earthquakes have: a record in g or m/s2 read as cm/s2? set record_units, record_scale'// &
                     trim(see('implausible-record'))
      end if
   end subroutine record_range_check

   !> A plausibility check's verdict and its word in the summary: warns when the figure is
   !> outside what structures and earthquakes have, else passed.
   pure subroutine plausible(c, outside)
      type(check_type), intent(inout) :: c   !! the check
      logical, intent(in) :: outside         !! its figure is outside the range

      c%verdict = merge(verdict_warns, verdict_passed, outside)
      c%outcome = verdict_names(c%verdict)
   end subroutine plausible

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
