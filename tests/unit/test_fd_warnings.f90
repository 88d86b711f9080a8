!> Unit tests of the warnings' texts (fd_warnings), the one wording the executable prints,
!> the summary holds and Python issues: none for a clean result; the figures a warning
!> carries, from a result set by hand (its formats: fixed with a zero before the point,
!> scientific with three digits); the device a warning names and the count of the others.
module test_fd_warnings
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_result, only: result_type, record_system_both
   use fd_warnings, only: warning_text, run_warnings, run_checks, n_checks
   use fd_check, only: check_type, figure_of
   implicit none
   private

   public :: collect_warnings

contains

   subroutine collect_warnings(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("a clean result: none", test_none), &
                  new_unittest("violations: the first times listed", test_violations), &
                  new_unittest("the band: the device, its figures, the others", test_band), &
                  new_unittest("the energy balance: dissipated or created", test_energy), &
                  new_unittest("a run that blew up: figures of 1e40", test_huge), &
                  new_unittest("a first period beyond 0.01-10 s: the unit typed wrong", test_period), &
                  new_unittest("a record's peak beyond 0.005-3 g: the units read wrong", test_record_peak), &
                  new_unittest("every warning: one line, short, its explanation named", test_one_line) &
                  ]
   end subroutine collect_warnings

   subroutine test_none(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      type(warning_text), allocatable :: w(:)

      call run_warnings(res, w)
      call check(error, size(w), 0)
   end subroutine test_none

   !> 12 violations, the first max_violation_times = 10 of them kept: listed, with six decimals.
   subroutine test_violations(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      type(warning_text), allocatable :: w(:)
      integer :: k

      res%violations = 12
      res%n_violation_times = 10
      res%violation_time(1:10) = [(0.05_dp*k, k=1, 10)]
      call run_warnings(res, w)
      call check(error, size(w), 1)
      if (allocated(error)) return
      call check(error, w(1)%text, '12 step(s) violate the correctness condition (eqs. 9, 12), first at t = '// &
                 '0.050000, 0.100000, 0.150000, ... s (correctness_violations): lower dt_min or widen eps, eps1; '// &
                 'see docs/warnings.md#correctness')
   end subroutine test_violations

   !> Two devices alternate: the larger (device 3, x = 4 at dt1 = 0.01 s) is named, with the
   !> step that brings x below 1, dt1 / x = 2.5e-3 s, and one more device.
   subroutine test_band(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      type(warning_text), allocatable :: w(:)
      type(check_type) :: checks(n_checks)
      real(dp) :: device, more
      logical :: found

      res%band_checked = .true.
      res%newmark%ran = .true.
      res%newmark%setup%dt1 = 0.01_dp
      res%band_alternation = [0.5_dp, 0.0_dp, 2.5_dp]
      res%band_alternation_time = [0.1_dp, 0.0_dp, 0.125_dp]
      res%band_x = [2.0_dp, 0.5_dp, 4.0_dp]
      call run_warnings(res, w)
      call check(error, size(w), 1)
      if (allocated(error)) return
      call check(error, w(1)%text, 'the force of device 3 alternates step to step in its band '// &
                 '(band_alternation_N = +-2.500E+00 N, x = 4.000E+00, 1 more device(s)): raise n1 until '// &
                 'dt1 < 2.500E-03 s or widen eps; see docs/warnings.md#band-alternation')
      if (allocated(error)) return
      ! the check record carries the device, its figures and the count of the others
      call run_checks(res, checks)
      call check(error, checks(7)%key, 'band_resolution')
      if (allocated(error)) return
      call figure_of(checks(7), 'device', device, found)
      call check(error, found .and. device == 3.0_dp, "figure 'device' of band_resolution")
      if (allocated(error)) return
      call figure_of(checks(7), 'more_devices', more, found)
      call check(error, found .and. more == 1.0_dp, "figure 'more_devices' of band_resolution")
   end subroutine test_band

   !> A ratio of 0.0734 dissipated (7.3 %), or -0.0734 created, against the limit 0.05.
   subroutine test_energy(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      type(warning_text), allocatable :: w(:)

      res%newmark%ran = .true.
      res%newmark%setup%damping_method = .true.   ! gamma > 1/2: a positive residual is its damping
      res%e_residual_ratio = 0.0734_dp
      call run_warnings(res, w)
      call check(error, size(w), 1)
      if (allocated(error)) return
      call check(error, w(1)%text, 'the integration dissipated 7.3 % of the energy (|energy_residual_ratio| > '// &
                 '0.05): numerical damping (gamma or theta > 1/2); raise n1 or use gamma = theta = 1/2; '// &
                 'see docs/warnings.md#energy-balance')
      if (allocated(error)) return
      res%e_residual_ratio = -0.0734_dp   ! energy created: an error of the step
      call run_warnings(res, w)
      call check(error, index(w(1)%text, 'the integration created 7.3 % of the energy') == 1 .and. &
                 index(w(1)%text, 'an energy error of the step') > 0, w(1)%text)
   end subroutine test_energy

   !> A run that grows without bound reaches energy ratios and ringing ratios of 1e40 before
   !> its numbers stop being finite: written in scientific notation (a fixed format of
   !> that size would overflow its record and stop the program).
   subroutine test_huge(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      type(warning_text), allocatable :: w(:)

      res%e_residual_ratio = -1.0e40_dp
      res%stick_checked = .true.
      res%newmark%ran = .true.
      res%newmark%setup%dt1 = 0.2_dp
      res%stick_freq_error = [0.5_dp]
      res%stick_ringing = [1.0e45_dp]
      res%stick_margin = [0.0_dp]
      res%stick_ringing_ratio = [1.0e40_dp]
      call run_warnings(res, w)
      call check(error, size(w), 2)
      if (allocated(error)) return
      call check(error, index(w(1)%text, 'rings with 1.000E+45 N against a margin of 0.000E+00 N') > 0 .and. &
                 index(w(1)%text, '(stick_ringing_ratio = 1.00E+40 > 1)') > 0, w(1)%text)
      if (allocated(error)) return
      call check(error, index(w(2)%text, 'the integration created 1.0E+42 % of the energy') == 1, w(2)%text)
   end subroutine test_huge

   !> The stuck system's first period of 31.6 s (a storey stiffness in kN/m typed as N/m: 1000
   !> times too soft) and of 3.2 ms warn, naming the unit; 0.3 s passes; without a stuck period
   !> (every mass held to the table through its devices) the free system's first finite
   !> period is judged (here after a rigid-body mode); with neither the check does not apply.
   subroutine test_period(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      type(warning_text), allocatable :: w(:)

      res%newmark%ran = .true.
      res%newmark%setup%period_stuck = 31.6_dp
      call run_warnings(res, w)
      call check(error, size(w), 1)
      if (allocated(error)) return
      call check(error, w(1)%text, 'the first period T1 = 31.6 s (period_stuck_s) is beyond 10 s, longer than '// &
                 'structures have: a stiffness in kN/m typed as N/m?; see docs/warnings.md#implausible-period')
      if (allocated(error)) return
      res%newmark%setup%period_stuck = 3.2e-3_dp
      call run_warnings(res, w)
      call check(error, size(w), 1)
      if (allocated(error)) return
      call check(error, w(1)%text, 'the first period T1 = 3.20E-03 s (period_stuck_s) is below 0.01 s, shorter '// &
                 'than structures have: masses in t typed as kg, or a stiffness in N/mm typed as N/m?; '// &
                 'see docs/warnings.md#implausible-period')
      if (allocated(error)) return
      res%newmark%setup%period_stuck = 0.3_dp
      call run_warnings(res, w)
      call check(error, size(w), 0)
      if (allocated(error)) return
      res%newmark%setup%period_stuck = 0.0_dp
      call run_warnings(res, w)
      call check(error, size(w), 0)
      if (allocated(error)) return
      res%eng%free%n = 2
      res%eng%free%omega2 = [0.0_dp, 0.16_dp]
      res%eng%free%period = [huge(1.0_dp), 2.0_dp*acos(-1.0_dp)/0.4_dp]
      call run_warnings(res, w)
      call check(error, size(w), 1)
      if (allocated(error)) return
      call check(error, index(w(1)%text, 'T1 = 15.7 s (periods_free_s(2)) is beyond 10 s') > 0, w(1)%text)
   end subroutine test_period

   !> A record of 0.35 g passes; one in cm/s2 read as g (343 g) and one in g read as cm/s2
   !> (3.6e-4 g) warn, naming the units; a record of zeros (free vibration) is not judged.
   subroutine test_record_peak(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      type(warning_text), allocatable :: w(:)

      res%record_pga = 0.35_dp*9.80665_dp
      call run_warnings(res, w)
      call check(error, size(w), 0)
      if (allocated(error)) return
      res%record_pga = 0.35_dp*9.80665_dp*100.0_dp*9.80665_dp
      call run_warnings(res, w)
      call check(error, size(w), 1)
      if (allocated(error)) return
      call check(error, w(1)%text, 'the record peaks at 343.2 g (record.peak_acc_mps2 = 3.366E+03), beyond 3 g, '// &
                 'more than earthquakes have: a record in cm/s2 read as g or m/s2? set record_units; '// &
                 'see docs/warnings.md#implausible-record')
      if (allocated(error)) return
      res%record_pga = 0.35_dp*0.01_dp
      call run_warnings(res, w)
      call check(error, size(w), 1)
      if (allocated(error)) return
      call check(error, w(1)%text, 'the record peaks at 3.57E-04 g (record.peak_acc_mps2 = 3.500E-03), below '// &
                 '0.005 g, less than earthquakes have: a record in g or m/s2 read as cm/s2? set record_units, '// &
                 'record_scale; see docs/warnings.md#implausible-record')
      if (allocated(error)) return
      res%record_pga = 0.0_dp
      call run_warnings(res, w)
      call check(error, size(w), 0)
   end subroutine test_record_peak

   !> Every warning at once, with figures of their widest formats: each is one line of at most
   !> 220 characters (the executable adds its prefix) that names its section of
   !> docs/warnings.md.
   subroutine test_one_line(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      type(warning_text), allocatable :: w(:)
      integer :: k

      res%violations = 123456
      res%n_violation_times = 10
      res%violation_time(1:10) = [(12345.678901_dp*k, k=1, 10)]
      res%mu_unconverged = 123456
      res%mu_unconverged_time = 12345.678_dp
      res%mu_misfit = 1.234e-3_dp
      res%newmark%ran = .true.
      res%newmark%setup%dt1 = 1.234e-3_dp
      res%mode_checked = .true.
      res%omega_max = 1.234e5_dp
      res%harmonic_checked = .true.
      res%harmonic_error = [0.1_dp, 12.345_dp]
      res%eng%frequency = 0.25_dp
      res%record_checked = .true.
      res%record_error = [0.1_dp, 12.345_dp]
      res%record_system = record_system_both
      res%stick_checked = .true.
      res%stick_ringing_ratio = [12345.67_dp, 2.0_dp, 3.0_dp]
      res%stick_ringing = [1.234e5_dp, 1.0_dp, 1.0_dp]
      res%stick_margin = [1.234e2_dp, 1.0_dp, 1.0_dp]
      res%stick_freq_error = [0.5_dp, 0.1_dp, 0.1_dp]
      res%band_checked = .true.
      res%band_alternation = [1.234e4_dp, 1.0_dp, 1.0_dp]
      res%band_alternation_time = [1.234e1_dp, 1.0_dp, 1.0_dp]
      res%band_x = [1.234e3_dp, 1.0_dp, 1.0_dp]
      res%newmark%setup%exact_accounting = .true.   ! round-off beyond 1e-8: digits lost
      res%e_residual_ratio = 1.234e-5_dp
      res%newmark%setup%period_stuck = 1.234e5_dp
      res%record_pga = 1.234e7_dp
      call run_warnings(res, w)
      call check(error, size(w), 10)
      if (allocated(error)) return
      do k = 1, size(w)
         call check(error, len(w(k)%text) <= 220 .and. index(w(k)%text, new_line('a')) == 0 .and. &
                    index(w(k)%text, '; see docs/warnings.md#') > 0, w(k)%text)
         if (allocated(error)) return
      end do
      res%newmark%setup%exact_accounting = .false.
      res%e_residual_ratio = -1234.5_dp
      call run_warnings(res, w)
      k = size(w)
      call check(error, len(w(k)%text) <= 220 .and. index(w(k)%text, '; see docs/warnings.md#') > 0, w(k)%text)
   end subroutine test_one_line

end module test_fd_warnings
