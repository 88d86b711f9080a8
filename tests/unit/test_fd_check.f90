!> Unit tests of the check records (fd_check) and of the checks of a result (fd_warnings'
!> run_checks): a figure kept and found by name; the warnings a filter over the checks (each
!> check that warns gives its line, in order; a passed or not applicable check none); each
!> check's key, verdict and figures from a result set by hand.
module test_fd_check
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_check, only: check_type, warning_text, add_figure, figure_of, check_warnings, max_figures, &
                       verdict_not_applicable, verdict_passed, verdict_warns
   use fd_result, only: result_type
   use fd_warnings, only: run_checks, run_warnings, n_checks
   implicit none
   private

   public :: collect_check

contains

   subroutine collect_check(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("figures: kept by name, at most max_figures", test_figures), &
                  new_unittest("the warnings: a filter over the checks", test_filter), &
                  new_unittest("a clean result: every check passed or not applicable", test_clean), &
                  new_unittest("the highest modes: not applicable, passed, warns", test_mode), &
                  new_unittest("violations and the energy balance: key, verdict, figures", test_violations_energy), &
                  new_unittest("every warning is the line of a check that warns", test_every_warning) &
                  ]
   end subroutine collect_check

   subroutine test_figures(error)
      type(error_type), allocatable, intent(out) :: error
      type(check_type) :: c
      real(dp) :: x
      logical :: found
      integer :: k

      call add_figure(c, 'omega_max_dt1', 2.5_dp)
      call figure_of(c, 'omega_max_dt1', x, found)
      call check(error, found .and. x == 2.5_dp, 'omega_max_dt1 kept')
      if (allocated(error)) return
      call figure_of(c, 'dt1_s', x, found)
      call check(error, .not. found .and. x == 0.0_dp, 'no dt1_s')
      if (allocated(error)) return
      do k = 2, max_figures + 3
         call add_figure(c, 'f', real(k, dp))
      end do
      call check(error, c%n_figures, max_figures)
      if (allocated(error)) return
      call check(error, c%figure(max_figures), real(max_figures, dp))
   end subroutine test_figures

   !> Four checks: warns (a), passed, not applicable, warns (b): the lines a then b.
   subroutine test_filter(error)
      type(error_type), allocatable, intent(out) :: error
      type(check_type) :: c(4)
      type(warning_text), allocatable :: w(:)

      c(1)%verdict = verdict_warns
      c(1)%warning = 'a'
      c(2)%verdict = verdict_passed
      c(3)%verdict = verdict_not_applicable
      c(4)%verdict = verdict_warns
      c(4)%warning = 'b'
      call check_warnings(c, w)
      call check(error, size(w), 2)
      if (allocated(error)) return
      call check(error, w(1)%text == 'a' .and. w(2)%text == 'b', 'the lines in order')
      if (allocated(error)) return
      call check_warnings(c(2:3), w)
      call check(error, size(w), 0)
   end subroutine test_filter

   subroutine test_clean(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      type(check_type) :: c(n_checks)
      integer :: k

      call run_checks(res, c)
      do k = 1, n_checks
         call check(error, c(k)%verdict /= verdict_warns .and. .not. allocated(c(k)%warning) .and. &
                    len_trim(c(k)%key) > 0, c(k)%key)
         if (allocated(error)) return
      end do
      call check(error, c(3)%key == 'mode_resolution' .and. c(3)%verdict == verdict_not_applicable, c(3)%key)
   end subroutine test_clean

   !> omega_max dt1 = 1.5 (resolved, passed) and 3 (unresolved, warns with its figures).
   subroutine test_mode(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      type(check_type) :: c(n_checks)
      type(warning_text), allocatable :: w(:)
      real(dp) :: x
      logical :: found

      res%newmark%ran = .true.
      res%newmark%setup%dt1 = 0.01_dp
      res%omega_max = 150.0_dp
      res%mode_checked = .true.
      call run_checks(res, c)
      call check(error, c(3)%verdict == verdict_passed .and. .not. allocated(c(3)%warning), 'resolved: passed')
      if (allocated(error)) return
      call check(error, c(3)%outcome, 'resolved')
      if (allocated(error)) return
      call figure_of(c(3), 'omega_max_dt1', x, found)
      call check(error, found .and. abs(x - 1.5_dp) < 1.0e-12_dp, 'omega_max_dt1 = 1.5')
      if (allocated(error)) return
      res%omega_max = 300.0_dp
      call run_checks(res, c)
      call check(error, c(3)%verdict == verdict_warns .and. allocated(c(3)%warning), 'unresolved: warns')
      if (allocated(error)) return
      call check(error, c(3)%outcome, 'unresolved')
      if (allocated(error)) return
      call check(error, index(c(3)%warning, 'omega_max_dt1 = 3.00 > 2') > 0, c(3)%warning)
      if (allocated(error)) return
      call run_warnings(res, w)
      call check(error, size(w), 1)
      if (allocated(error)) return
      call check(error, w(1)%text == c(3)%warning, w(1)%text)
   end subroutine test_mode

   !> Two violations (their count and first times as figures) and a balance that lost
   !> digits: both warn; a closed balance passes.
   subroutine test_violations_energy(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      type(check_type) :: c(n_checks)
      real(dp) :: x
      logical :: found

      res%violations = 2
      res%n_violation_times = 2
      res%violation_time(1:2) = [0.25_dp, 0.5_dp]
      res%newmark%ran = .true.
      res%newmark%setup%exact_accounting = .true.   ! average acceleration: round-off only
      res%e_residual_ratio = 3.0e-8_dp
      call run_checks(res, c)
      call check(error, c(1)%key == 'correctness_violations' .and. c(1)%verdict == verdict_warns, c(1)%key)
      if (allocated(error)) return
      call figure_of(c(1), 'violation_times_s(2)', x, found)
      call check(error, found .and. x == 0.5_dp, 'the second time')
      if (allocated(error)) return
      call check(error, c(8)%key == 'energy_balance' .and. c(8)%verdict == verdict_warns .and. &
                 index(c(8)%warning, 'lost digits') > 0, c(8)%key)
      if (allocated(error)) return
      call check(error, c(8)%outcome, 'digits lost')
      if (allocated(error)) return
      res%newmark%setup%exact_accounting = .false.  ! a rule whose residual may reach 5 %
      call run_checks(res, c)
      call figure_of(c(8), 'energy_residual_ratio', x, found)
      call check(error, c(8)%verdict == verdict_passed .and. found .and. x == 3.0e-8_dp, 'closed: passed')
      if (allocated(error)) return
      call check(error, c(8)%outcome, 'closed')
   end subroutine test_violations_energy

   !> Every check warning at once: the warnings are their lines, one each, in order.
   subroutine test_every_warning(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      type(check_type) :: c(n_checks)
      type(warning_text), allocatable :: w(:)
      integer :: k

      res%violations = 1
      res%n_violation_times = 1
      res%violation_time(1) = 0.1_dp
      res%mu_unconverged = 1
      res%newmark%ran = .true.
      res%newmark%setup%dt1 = 0.01_dp
      res%mode_checked = .true.
      res%omega_max = 300.0_dp
      res%harmonic_checked = .true.
      res%harmonic_error = [0.2_dp]
      res%eng%frequency = 1.0_dp
      res%record_checked = .true.
      res%record_error = [0.2_dp]
      res%stick_checked = .true.
      res%stick_ringing_ratio = [2.0_dp]
      res%stick_ringing = [1.0_dp]
      res%stick_margin = [0.5_dp]
      res%band_checked = .true.
      res%band_alternation = [1.0_dp]
      res%band_x = [2.0_dp]
      res%newmark%setup%exact_accounting = .true.
      res%e_residual_ratio = 1.0e-6_dp
      res%newmark%setup%period_stuck = 30.0_dp
      res%record_pga = 1000.0_dp
      res%n_bearings = 2
      res%bearing_uplifts = [0, 2]
      res%bearing_uplift_time = [0.0_dp, 0.25_dp]
      res%bearing_uplift_first = [0.0_dp, 1.5_dp]
      call run_checks(res, c)
      call run_warnings(res, w)
      call check(error, size(w), n_checks)
      if (allocated(error)) return
      do k = 1, n_checks
         call check(error, c(k)%verdict == verdict_warns .and. w(k)%text == c(k)%warning, c(k)%key)
         if (allocated(error)) return
      end do
      ! the uplift's line names the bearing that stayed lifted longest, its time and first start
      call check(error, index(w(n_checks)%text, '1 bearing(s) lifted off') == 1 .and. &
                 index(w(n_checks)%text, 'bearing 2 for 2.500E-01 s from t = 1.500E+00 s') > 0 .and. &
                 len_trim(w(n_checks)%text) <= 220, w(n_checks)%text)
   end subroutine test_every_warning

end module test_fd_check
