!> Unit tests of the observer (fd_observer) that every technique reports to: the history
!> rows and their layout, the sampling grid, peaks and their times, transitions,
!> correctness violations, and the closing of the energy balance.
module test_fd_observer
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use test_fd_helpers, only: pairs_of
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_model, only: model_type, device_type, integration_type, law_velocity
   use fd_excitation, only: excitation_type, excitation_none
   use fd_result, only: result_type, max_violation_times, check_finite, nonfinite_history_error
   use fd_run_control, only: run_control, select_history
   use fd_row_sink, only: row_sink
   use fd_names, only: technique_event_driven
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf
   use fd_observer, only: observer_type, observed_state, observer_init, sample_due, observe_start, observe_peaks, &
                          observe_sample, observe_transitions, observe_violations, observe_end, &
                          observe_extrema, observe_extremum, observe_work, observe_poll, observe_stop_error, &
                          observe_device_motion, observe_start_energies, observe_end_energies, &
                          observe_bearing_forces
   use fd_vertical_support, only: vertical_support
   implicit none
   private

   public :: collect_observer

   !> A row sink in memory: the header, the rows put and a failure to report.
   type, extends(row_sink) :: memory_sink
      character(len=:), allocatable :: header
      integer :: rows = 0
      real(dp) :: last(10) = 0.0_dp
      logical :: broken = .false.
      logical :: finished = .false.
   contains
      procedure :: begin => memory_begin
      procedure :: put => memory_put
      procedure :: failed => memory_failed
      procedure :: finish => memory_finish
      procedure :: discard => memory_discard
   end type memory_sink

contains

   subroutine collect_observer(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("sampling grid and history rows", test_history), &
                  new_unittest("peaks and their times", test_peaks), &
                  new_unittest("phase transitions", test_transitions), &
                  new_unittest("correctness violations", test_violations), &
                  new_unittest("energy balance of a free oscillator", test_energy), &
                  new_unittest("a non-finite result named", test_non_finite), &
                  new_unittest("a non-finite row outside the result noted", test_non_finite_buffer), &
                  new_unittest("maxima between rows of the kept DOFs and devices", test_selected_envelope), &
                  new_unittest("exact extrema in the envelope's order", test_extrema), &
                  new_unittest("the work of the steps into the balance", test_work), &
                  new_unittest("each device's work, dissipation and slip travel", test_device_work), &
                  new_unittest("rows into the control's row sink; its failure stops the run", test_sink), &
                  new_unittest("a bearing's travel, reversals and the isolation shear", test_bearing_orbit), &
                  new_unittest("the bearings' normal forces, extremes and uplift", test_bearing_forces) &
                  ]
   end subroutine collect_observer

   !> Two masses, one device, table at rest for 25 steps of dt1 = 0.5 ms, a row every 20.
   subroutine setup(model, res, obs, error)
      type(model_type), intent(out) :: model
      type(result_type), intent(out) :: res
      type(observer_type), intent(out) :: obs
      type(error_type), allocatable, intent(out) :: error
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(fd_error_type), allocatable :: err

      model%n_dof = 2
      model%mass = [2.0_dp, 1.0_dp]
      model%n_devices = 1
      model%dev = [device_type(node_i=1, node_j=2, law=law_velocity, p=10.0_dp, mu=0.2_dp)]
      call pairs_of(model)
      exc%kind = excitation_none
      exc%dt_record = 0.01_dp
      exc%duration = 0.0123_dp
      opts%n1 = 20
      call observer_init(model, exc, opts, 0.0_dp, res, obs, err)
      if (allocated(err)) call test_failed(error, err%message)
   end subroutine setup

   subroutine test_history(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(observer_type) :: obs
      integer :: k, due(25), i

      call setup(model, res, obs, error)
      if (allocated(error)) return
      ! nint(0.0123 / 5e-4) = 25 steps: rows at t = 0, after step 20 and at the end
      call check(error, obs%nsteps == 25 .and. res%nout == 3 .and. res%ncol == 2 + 3*2 + 4*1, &
                 "history shape")
      if (allocated(error)) return
      due = 0
      do k = 1, 25
         if (sample_due(obs, k)) due(k) = 1
      end do
      call check(error, sum(due) == 2 .and. due(20) == 1 .and. due(25) == 1, "rows after steps 20 and 25")
      if (allocated(error)) return
      do i = 1, 4   ! the fourth row is beyond the history and is not written
         call observe_sample(obs, res, 0.01_dp*i, -0.5_dp*i, [1.0_dp, 2.0_dp]*i, [3.0_dp, 4.0_dp]*i, &
                             [5.0_dp, 6.0_dp]*i, [7.0_dp]*i, [8.0_dp]*i, [9.0_dp]*i, [-1])
      end do
      call check(error, obs%rows == 4, "rows counted")
      if (allocated(error)) return
      ! the device slides in the first row (t = 0): a slip excursion, the later rows none
      call check(error, res%slip_excursions(1) == 1 .and. res%stick_to_slip(1) == 0, "a slide at t = 0")
      if (allocated(error)) return
      ! t, ag, (u, v, aabs = a + ag) per DOF, (s, s', F, phase) per device
      call check(error, all(res%hist(:, 2) == [0.02_dp, -1.0_dp, 2.0_dp, 6.0_dp, 9.0_dp, 4.0_dp, 8.0_dp, &
                                               11.0_dp, 14.0_dp, 16.0_dp, 18.0_dp, -1.0_dp]), &
                 "layout of a history row")
   end subroutine test_history

   subroutine test_peaks(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(observer_type) :: obs

      call setup(model, res, obs, error)
      if (allocated(error)) return
      call observe_peaks(res, 0.1_dp, observed_state(2, 1, 2.0_dp, 0.0_dp, [0.01_dp, 0.0_dp], [0.5_dp, -0.1_dp], &
                                                     [1.0_dp, 0.0_dp], [0.01_dp], [3.0_dp]))
      call observe_peaks(res, 0.2_dp, observed_state(2, 1, -4.0_dp, 0.0_dp, [-0.03_dp, 0.02_dp], [-0.7_dp, 0.2_dp], &
                                                     [-1.0_dp, 0.0_dp], [-0.05_dp], [-1.0_dp]))
      call observe_peaks(res, 0.3_dp, observed_state(2, 1, 0.0_dp, 0.0_dp, [0.02_dp, 0.01_dp], [0.1_dp, 0.3_dp], &
                                                     [0.0_dp, 5.5_dp], [0.02_dp], [2.0_dp]))
      ! |u| and its time; |v|; |a + ag| (absolute acceleration) and its time
      call check(error, all(res%peak_u == [0.03_dp, 0.02_dp]) .and. all(res%peak_u_time == [0.2_dp, 0.2_dp]), &
                 "peak |u| and its time")
      if (allocated(error)) return
      call check(error, all(res%peak_v == [0.7_dp, 0.3_dp]), "peak |v|")
      if (allocated(error)) return
      call check(error, all(res%peak_aabs == [5.0_dp, 5.5_dp]) .and. &
                 all(res%peak_aabs_time == [0.2_dp, 0.3_dp]), "peak |aabs| and its time")
      if (allocated(error)) return
      call check(error, res%peak_s(1) == 0.05_dp .and. res%peak_force(1) == 3.0_dp, "peak |s| and |F|")
      if (allocated(error)) return
      ! the residual displacement: the last state's s, not its peak
      call check(error, res%eng%residual_s(1) == 0.02_dp, "residual s: the last state's")
   end subroutine test_peaks

   !> A friction pendulum bearing (p = 10 N, mu = 0.2, R = 2 m: restoring stiffness 5 N/m) on a
   !> circle of radius 0.4 m in steps of 45 degrees, its friction force mu P along the tangent:
   !> each chord 0.8 sin(pi/8), the force turning 675 degrees after the slide's first step
   !> (3 reversals), the shear (F + 5 s) of magnitude sqrt(2^2 + 2^2) and max |V_x| at 135
   !> degrees. Once it sticks, a force turned back is no reversal, and a step no travel.
   subroutine test_bearing_orbit(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(observer_type) :: obs
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(fd_error_type), allocatable :: err
      real(dp), parameter :: pi = acos(-1.0_dp), r = 0.4_dp
      real(dp) :: th, s(2), f(2), z(2)
      integer :: k

      model%n_dof = 2
      model%mass = [1.0_dp, 1.0_dp]
      model%n_devices = 2
      model%dev = [device_type(node_i=1, node_j=0, law=law_velocity, p=10.0_dp, mu=0.2_dp, partner=2, component=1, &
                               radius=2.0_dp), &
                   device_type(node_i=2, node_j=0, law=law_velocity, p=10.0_dp, mu=0.2_dp, partner=1, component=2, &
                               radius=2.0_dp)]
      call pairs_of(model)
      exc%kind = excitation_none
      exc%dt_record = 0.01_dp
      exc%duration = 0.2_dp
      opts%n1 = 1
      call observer_init(model, exc, opts, 0.0_dp, res, obs, err)
      call check(error, .not. allocated(err), "observer_init")
      if (allocated(error)) return
      call check(error, res%n_bearings, 1)
      if (allocated(error)) return
      z = 0.0_dp
      call observe_peaks(res, 0.0_dp, observed_state(2, 2, 0.0_dp, 0.0_dp, z, z, z, [r, 0.0_dp], z))
      call observe_transitions(res, [0, 0], [1, 1])
      do k = 1, 16
         th = k*pi/4
         s = r*[cos(th), sin(th)]
         f = 2.0_dp*[-sin(th), cos(th)]
         call observe_peaks(res, 0.01_dp*k, observed_state(2, 2, 0.0_dp, 0.0_dp, s, z, z, s, f))
      end do
      call check(error, abs(res%bearing_travel(1) - 16*2*r*sin(pi/8)) <= 1e-14_dp, "travel: the chords")
      if (allocated(error)) return
      call check(error, res%bearing_reversals(1), 3)
      if (allocated(error)) return
      call check(error, abs(res%peak_iso_shear(3) - sqrt(8.0_dp)) <= 1e-14_dp .and. &
                 abs(res%peak_iso_shear(1) - sqrt(8.0_dp)) <= 1e-14_dp, "isolation shear |V|, |V_x|")
      if (allocated(error)) return
      call check(error, abs(res%peak_iso_shear_time(1) - 0.03_dp) <= 1e-15_dp, "time of max |V_x| (135 degrees)")
      if (allocated(error)) return
      ! it sticks at the end of a step taken sliding (whose chord counts), then moves stuck:
      ! neither travel nor reversals, whatever its force does
      call observe_transitions(res, [1, 1], [0, 0])
      call observe_peaks(res, 0.17_dp, observed_state(2, 2, 0.0_dp, 0.0_dp, z, z, z, s, [0.0_dp, -2.0_dp]))
      call observe_peaks(res, 0.18_dp, observed_state(2, 2, 0.0_dp, 0.0_dp, z, z, z, [r, 0.01_dp], [0.0_dp, 2.0_dp]))
      call check(error, res%bearing_reversals(1) == 3 .and. &
                 abs(res%bearing_travel(1) - 16*2*r*sin(pi/8)) <= 1e-14_dp, "a stuck bearing")
   end subroutine test_bearing_orbit

   subroutine test_transitions(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(observer_type) :: obs
      integer :: i
      integer, parameter :: phases(*) = [0, 1, 1, 0, -1, 1, -1, 0, 0]

      call setup(model, res, obs, error)
      if (allocated(error)) return
      do i = 2, size(phases)
         call observe_transitions(res, phases(i - 1:i - 1), phases(i:i))
      end do
      ! stick->slip at 0->1 and 0->-1; slip->stick at 1->0 and -1->0; reversals -1->1, 1->-1
      call check(error, res%stick_to_slip(1) == 2 .and. res%slip_to_stick(1) == 2 .and. res%reversals(1) == 2, &
                 "transition counts")
      if (allocated(error)) return
      ! two slides (a reversal continues one)
      call check(error, res%slip_excursions(1), 2)
   end subroutine test_transitions

   subroutine test_violations(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(observer_type) :: obs
      integer :: i

      call setup(model, res, obs, error)
      if (allocated(error)) return
      call observe_violations(res, 0.5_dp, [.true.])
      do i = 1, 12
         call observe_violations(res, 1.0_dp*i, [.false.])
      end do
      call check(error, res%violations == 12 .and. res%n_violation_times == max_violation_times, &
                 "every violation counted, the first ones kept")
      if (allocated(error)) return
      call check(error, res%violation_time(1) == 1.0_dp .and. res%violation_time(10) == 10.0_dp .and. &
                 all(res%violation_device(1:10) == 1), "times and devices of the first violations")
   end subroutine test_violations

   !> An undamped oscillator from its extreme (u0, v = 0) to its centre (u = 0, v = w u0):
   !> the kinetic energy gained is the strain energy lost, and the residual is round-off;
   !> friction dissipation is device work minus the change of stored device energy.
   subroutine test_energy(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(observer_type) :: obs
      real(dp) :: k(2, 2), tmp(2), m(2), u0, w, e

      call setup(model, res, obs, error)
      if (allocated(error)) return
      m = [2.0_dp, 1.0_dp]
      k = reshape([800.0_dp, 0.0_dp, 0.0_dp, 100.0_dp], [2, 2])
      u0 = 0.01_dp
      w = sqrt(800.0_dp/2.0_dp)
      e = 0.5_dp*800.0_dp*u0**2
      call observe_start(obs, m, k, [u0, 0.0_dp], [0.0_dp, 0.0_dp], 0.3_dp, tmp)
      call observe_end(obs, res, m, k, [0.0_dp, 0.0_dp], [w*u0, 0.0_dp], 0.2_dp, 1.0_dp, tmp)
      call check(error, res%e_kinetic, e, rel=.true., thr=1.0e-15_dp)
      if (allocated(error)) return
      call check(error, res%e_strain, -e, rel=.true., thr=1.0e-15_dp)
      if (allocated(error)) return
      call check(error, res%e_device, -0.1_dp, thr=1.0e-16_dp)
      if (allocated(error)) return
      call check(error, res%e_friction, 1.1_dp, thr=1.0e-15_dp)
      if (allocated(error)) return
      ! no input, no viscous work: the friction work is the only imbalance
      call check(error, res%e_residual, -(res%e_friction + res%e_device), thr=1.0e-15_dp)
   end subroutine test_energy

   !> check_finite: a finite result passes; an overflowed energy, peak, history value or
   !> engineering output is an error naming its summary key (or column and time), never a
   !> null in a summary.
   subroutine test_non_finite(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res, bad
      type(observer_type) :: obs
      type(fd_error_type), allocatable :: err

      call setup(model, res, obs, error)
      if (allocated(error)) return
      call check_finite(res, err)
      call check(error, .not. allocated(err), 'a finite result')
      if (allocated(error)) return
      bad = res
      bad%e_input = ieee_value(1.0_dp, ieee_positive_inf)
      call check_finite(bad, err)
      call check(error, allocated(err), 'an infinite energy')
      if (allocated(error)) return
      call check(error, index(err%message, 'energy_input_J = Inf') > 0, err%message)
      if (allocated(error)) return
      bad = res
      bad%peak_force(1) = ieee_value(1.0_dp, ieee_quiet_nan)
      call check_finite(bad, err)
      call check(error, allocated(err), 'a NaN peak')
      if (allocated(error)) return
      call check(error, index(err%message, 'peak_force_N(1) = NaN') > 0, err%message)
      if (allocated(error)) return
      bad = res
      bad%hist(1, 2) = 0.01_dp
      bad%hist(4, 2) = -ieee_value(1.0_dp, ieee_positive_inf)
      call check_finite(bad, err)
      call check(error, allocated(err), 'an infinite history value')
      if (allocated(error)) return
      call check(error, index(err%message, 'history column v1 at t = 0.01 s is -Inf') > 0, err%message)
      if (allocated(error)) return
      ! the engineering outputs (fd_engineering) too: base shear, residual device displacement
      bad = res
      bad%eng%peak_shear(0) = ieee_value(1.0_dp, ieee_positive_inf)
      call check_finite(bad, err)
      call check(error, allocated(err), 'an infinite base shear')
      if (allocated(error)) return
      call check(error, index(err%message, 'peak_base_shear_N = Inf') > 0, err%message)
      if (allocated(error)) return
      bad = res
      bad%eng%residual_s(1) = ieee_value(1.0_dp, ieee_quiet_nan)
      call check_finite(bad, err)
      call check(error, allocated(err), 'a NaN residual displacement')
      if (allocated(error)) return
      call check(error, index(err%message, 'residual_s_m(1) = NaN') > 0, err%message)
   end subroutine test_non_finite

   !> A row that goes only to the caller's buffer (the history file alike) is not in the
   !> result that check_finite sees: the observer notes its first value not finite in the
   !> control, for run_config_solve's error (the same message as check_finite's).
   subroutine test_non_finite_buffer(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(observer_type) :: obs
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(run_control), target :: ctl
      type(fd_error_type), allocatable :: err
      real(dp), target :: buf(12, 3)
      real(dp) :: nan

      nan = ieee_value(1.0_dp, ieee_quiet_nan)
      model%n_dof = 2
      model%mass = [2.0_dp, 1.0_dp]
      model%n_devices = 1
      model%dev = [device_type(node_i=1, node_j=2, law=law_velocity, p=10.0_dp, mu=0.2_dp)]
      call pairs_of(model)
      exc%kind = excitation_none
      exc%dt_record = 0.01_dp
      exc%duration = 0.0123_dp
      opts%n1 = 20
      ctl%buffer => buf
      ctl%keep = .false.
      call observer_init(model, exc, opts, 0.0_dp, res, obs, err, ctl)
      if (allocated(err)) call test_failed(error, err%message)
      if (allocated(error)) return
      call check(error, size(res%hist, 2) == 0 .and. res%nout == 3, 'no rows in the result')
      if (allocated(error)) return
      call observe_sample(obs, res, 0.0_dp, 0.0_dp, [1.0_dp, 2.0_dp], [0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], &
                          [1.0_dp], [0.0_dp], [0.0_dp], [0])
      call check(error, ctl%bad_column == 0, 'a finite row')
      if (allocated(error)) return
      call observe_sample(obs, res, 0.01_dp, 0.0_dp, [1.0_dp, 2.0_dp], [0.0_dp, nan], [0.0_dp, 0.0_dp], &
                          [1.0_dp], [0.0_dp], [nan], [0])
      call check(error, ctl%bad_column == 7 .and. ctl%bad_time == 0.01_dp, 'the first NaN: v2 at t = 0.01 s')
      if (allocated(error)) return
      call check(error, buf(7, 2) /= buf(7, 2), 'the row is in the buffer as computed')
      if (allocated(error)) return
      call check_finite(res, err)
      call check(error, .not. allocated(err), 'the result itself holds no row')
      if (allocated(error)) return
      call nonfinite_history_error(res%names(ctl%bad_column), ctl%bad_time, ctl%bad_value, err)
      call check(error, index(err%message, 'history column v2 at t = 0.01 s is NaN') > 0, err%message)
   end subroutine test_non_finite_buffer

   !> The exact technique's maxima between rows (peak_*) follow the history selection: the
   !> columns of the DOFs and devices kept, in their order, their values from the full list.
   subroutine test_selected_envelope(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(observer_type) :: obs
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(run_control), target :: ctl
      type(fd_error_type), allocatable :: err
      real(dp) :: env(3*3 + 2*2)
      integer :: i

      model%n_dof = 3
      model%mass = [1.0_dp, 1.0_dp, 1.0_dp]
      model%n_devices = 2
      model%dev = [device_type(node_i=1, node_j=0, law=law_velocity, p=1.0_dp, mu=0.1_dp), &
                   device_type(node_i=3, node_j=2, law=law_velocity, p=1.0_dp, mu=0.1_dp)]
      call pairs_of(model)
      exc%kind = excitation_none
      exc%dt_record = 0.01_dp
      exc%duration = 0.01_dp
      opts%n1 = 1
      opts%technique = technique_event_driven
      call select_history(ctl, [3], [2], 3, 2, err)
      if (allocated(err)) call test_failed(error, err%message)
      if (allocated(error)) return
      call observer_init(model, exc, opts, 0.0_dp, res, obs, err, ctl)
      if (allocated(err)) call test_failed(error, err%message)
      if (allocated(error)) return
      call check(error, res%ncol == 2 + 3 + 4 + 3 + 2, 'columns: t, ag, 3 of DOF 3, 4 of device 2, 3 + 2 maxima')
      if (allocated(error)) return
      call check(error, res%names(10) == 'peak_u3' .and. res%names(12) == 'peak_aabs3' .and. &
                 res%names(13) == 'peak_s2' .and. res%names(14) == 'peak_F2', 'names of the kept maxima')
      if (allocated(error)) return
      env = [(real(i, dp), i=1, size(env))]
      call observe_sample(obs, res, 0.0_dp, 0.0_dp, [0.0_dp, 0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp, 0.0_dp], &
                          [0.0_dp, 0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], [0, 0], env)
      ! DOF 3: entries 7, 8, 9; device 2: entries 9 + 3, 9 + 4
      call check(error, all(res%hist(10:14, 1) == [7.0_dp, 8.0_dp, 9.0_dp, 12.0_dp, 13.0_dp]), &
                 'the maxima of DOF 3 and device 2')
   end subroutine test_selected_envelope

   !> Two DOFs and one device: the quantities |u1|, |v1|, |aabs1|, |u2|, |v2|, |aabs2|, |s1|,
   !> |F1| go to their peaks (with the times of u and aabs); a smaller value leaves a peak.
   subroutine test_extrema(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(observer_type) :: obs

      call setup(model, res, obs, error)
      if (allocated(error)) return
      call observe_extrema(res, [0.1_dp, -0.2_dp, 0.3_dp, -0.4_dp, 0.5_dp, -0.6_dp, 0.7_dp, -80.0_dp], 0.25_dp)
      call check(error, all(res%peak_u == [0.1_dp, 0.4_dp]) .and. all(res%peak_v == [0.2_dp, 0.5_dp]) .and. &
                 all(res%peak_aabs == [0.3_dp, 0.6_dp]) .and. all(res%peak_u_time == 0.25_dp) .and. &
                 all(res%peak_aabs_time == 0.25_dp), 'the DOFs')
      if (allocated(error)) return
      call check(error, res%peak_s(1) == 0.7_dp .and. res%peak_force(1) == 80.0_dp, 'the device')
      if (allocated(error)) return
      call observe_extremum(res, 4, 0.3_dp, 0.5_dp)
      call observe_extremum(res, 7, 0.9_dp, 0.5_dp)
      call check(error, res%peak_u(2) == 0.4_dp .and. res%peak_u_time(2) == 0.25_dp .and. res%peak_s(1) == 0.9_dp, &
                 'a smaller |u2| leaves its peak, a larger |s1| replaces it')
   end subroutine test_extrema

   !> Input work -2 J then +1 J, viscous 0.5 J each: input -1 J, gross 3 J, viscous 1 J.
   subroutine test_work(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res

      call observe_work(res, -2.0_dp, 0.5_dp)
      call observe_work(res, 1.0_dp, 0.5_dp)
      call check(error, res%e_input == -1.0_dp .and. res%e_input_gross == 3.0_dp .and. res%e_viscous == 1.0_dp, &
                 'the balance')
   end subroutine test_work

   !> Two devices: device 1 sticks (elastic work 0.3 J, stored at the end) then slides 0.02 m
   !> at 50 N (1 J); device 2 slides 0.01 m at 20 N, 0.03 m at 20 N (0.8 J) and back 0.005 m
   !> (0.1 J). Each one's dissipation is its work less the elastic energy it stored (0.05 J
   !> at the start, 0.25 J at the end, device 1), its travel only what it slid; the devices'
   !> dissipations sum to energy_friction_J.
   subroutine test_device_work(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(observer_type) :: obs

      call setup(model, res, obs, error)
      if (allocated(error)) return
      model%n_devices = 2
      model%dev = [model%dev(1), model%dev(1)]
      call pairs_of(model)
      call reinit(model, res, obs, error)
      if (allocated(error)) return
      call observe_start_energies(obs, 0.0_dp, 0.0_dp, 0.05_dp, [0.05_dp, 0.0_dp])
      ! a technique's own loop adds to the observer's totals (Newmark), or it calls
      ! observe_device_motion
      obs%device_work = obs%device_work + [0.3_dp, 0.2_dp]
      obs%slip_travel = obs%slip_travel + [0.0_dp, 0.01_dp]
      call observe_device_motion(obs, 1, 1.0_dp, 0.02_dp)
      call observe_device_motion(obs, 2, 0.6_dp, 0.03_dp)
      call observe_device_motion(obs, 2, 0.1_dp, 0.005_dp)
      call observe_end_energies(obs, res, 0.0_dp, 0.0_dp, 0.25_dp, 2.2_dp, [0.25_dp, 0.0_dp])
      call check(error, obs%device_work(1), 1.3_dp, thr=1.0e-15_dp)
      if (allocated(error)) return
      call check(error, obs%device_work(2), 0.9_dp, thr=1.0e-15_dp)
      if (allocated(error)) return
      call check(error, res%dissipated(1), 1.1_dp, thr=1.0e-15_dp)
      if (allocated(error)) return
      call check(error, res%dissipated(2), 0.9_dp, thr=1.0e-15_dp)
      if (allocated(error)) return
      call check(error, sum(res%dissipated), res%e_friction, thr=1.0e-15_dp)
      if (allocated(error)) return
      call check(error, res%slip_travel(1), 0.02_dp, thr=1.0e-17_dp)
      if (allocated(error)) return
      call check(error, res%slip_travel(2), 0.045_dp, thr=1.0e-17_dp)
   contains
      subroutine reinit(model, res, obs, error)
         type(model_type), intent(in) :: model
         type(result_type), intent(out) :: res
         type(observer_type), intent(out) :: obs
         type(error_type), allocatable, intent(out) :: error
         type(excitation_type) :: exc
         type(integration_type) :: opts
         type(fd_error_type), allocatable :: err

         exc%kind = excitation_none
         exc%dt_record = 0.01_dp
         exc%duration = 0.0123_dp
         opts%n1 = 20
         call observer_init(model, exc, opts, 0.0_dp, res, obs, err)
         if (allocated(err)) call test_failed(error, err%message)
      end subroutine reinit
   end subroutine test_device_work

   !> A run whose control holds a row sink: begun with the history's header, each row put
   !> into it (none into the result); a failed write makes the next look at the clock say
   !> stop, and the stop error is the sink's own.
   subroutine test_sink(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(observer_type) :: obs
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(run_control), target :: ctl
      type(fd_error_type), allocatable :: err
      logical :: halt
      integer :: k

      model%n_dof = 2
      model%mass = [2.0_dp, 1.0_dp]
      model%n_devices = 1
      model%dev = [device_type(node_i=1, node_j=2, law=law_velocity, p=10.0_dp, mu=0.2_dp)]
      call pairs_of(model)
      exc%kind = excitation_none
      exc%dt_record = 0.01_dp
      exc%duration = 0.0123_dp
      opts%n1 = 20
      ctl%keep = .false.
      allocate (memory_sink :: ctl%sink)
      call observer_init(model, exc, opts, 0.0_dp, res, obs, err, ctl)
      if (allocated(err)) call test_failed(error, err%message)
      if (allocated(error)) return
      call observe_sample(obs, res, 0.0_dp, -0.5_dp, [1.0_dp, 2.0_dp], [3.0_dp, 4.0_dp], [0.0_dp, 0.0_dp], &
                          [5.0_dp], [6.0_dp], [7.0_dp], [1])
      select type (sink => ctl%sink)
      type is (memory_sink)
         call check(error, sink%header, 't[s],ag[m/s2],u1[m],v1[m/s],aabs1[m/s2],u2[m],v2[m/s],aabs2[m/s2],'// &
                    's1[m],sdot1[m/s],F1[N],phase1[-]')
         if (allocated(error)) return
         call check(error, sink%rows == 1 .and. sink%last(3) == 1.0_dp .and. sink%last(10) == 6.0_dp .and. &
                    size(res%hist, 2) == 0, 'the row in the sink, none in the result')
         if (allocated(error)) return
         sink%broken = .true.
      end select
      halt = .false.
      do k = 1, 2100000
         call observe_poll(obs, 0.001_dp*k, halt)
         if (halt) exit
      end do
      call check(error, halt, 'a failed sink stops the run')
      if (allocated(error)) return
      call observe_stop_error(obs, err)
      call check(error, allocated(err), 'the stop error')
      if (allocated(error)) return
      call check(error, err%message, 'memory sink: broken')
   end subroutine test_sink

   subroutine memory_begin(sink, header, ncol, error)
      class(memory_sink), intent(inout) :: sink
      character(len=*), intent(in) :: header
      integer, intent(in) :: ncol
      type(fd_error_type), allocatable, intent(out) :: error
      sink%header = header
      if (ncol /= 12) allocate (error)
   end subroutine memory_begin

   subroutine memory_put(sink, row)
      class(memory_sink), intent(inout) :: sink
      real(dp), intent(in) :: row(:)
      sink%rows = sink%rows + 1
      sink%last(1:min(10, size(row))) = row(1:min(10, size(row)))
   end subroutine memory_put

   logical function memory_failed(sink)
      class(memory_sink), intent(in) :: sink
      memory_failed = sink%broken
   end function memory_failed

   subroutine memory_finish(sink, error)
      class(memory_sink), intent(inout) :: sink
      type(fd_error_type), allocatable, intent(out) :: error
      sink%finished = .true.
      if (sink%broken) then
         allocate (error)
         error%message = 'memory sink: broken'
      end if
   end subroutine memory_finish

   subroutine memory_discard(sink)
      class(memory_sink), intent(inout) :: sink
      sink%rows = 0
   end subroutine memory_discard

   !> A planar bearing of N0 = 10 N (p_static): at a vertical table acceleration az its normal
   !> force is N0 (1 + az / g), with the overturning's dN added (tilt); the observer keeps its
   !> extremes and counts an uplift (N <= 0) once, at the state where it starts.
   subroutine test_bearing_forces(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(observer_type) :: obs
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(vertical_support) :: rigid
      type(fd_error_type), allocatable :: err
      real(dp), parameter :: g = 9.80665_dp
      real(dp) :: pn(2)

      model%n_dof = 2
      model%mass = [1.0_dp, 1.0_dp]
      model%n_devices = 2
      model%dev = [device_type(node_i=1, node_j=0, law=law_velocity, p=10.0_dp, mu=0.2_dp, partner=2, component=1, &
                               radius=2.0_dp, p_static=10.0_dp), &
                   device_type(node_i=2, node_j=0, law=law_velocity, p=10.0_dp, mu=0.2_dp, partner=1, component=2, &
                               radius=2.0_dp, p_static=10.0_dp)]
      call pairs_of(model)
      exc%kind = excitation_none
      exc%dt_record = 0.01_dp
      exc%duration = 0.2_dp
      opts%n1 = 1
      call observer_init(model, exc, opts, 0.0_dp, res, obs, err)
      call check(error, .not. allocated(err) .and. res%n_bearings == 1, "observer_init: one bearing")
      if (allocated(error)) return
      call observe_bearing_forces(res, model, 0.0_dp, 0.0_dp, -0.5_dp*g, .false., rigid, pn)
      call check(error, abs(pn(1) - 5.0_dp) <= 1e-14_dp .and. res%bearing_n_min(1) == pn(1) .and. &
                 res%bearing_n_max(1) == pn(1), "N0 (1 + az / g) at the start")
      if (allocated(error)) return
      call observe_bearing_forces(res, model, 0.01_dp, 0.01_dp, 0.0_dp, .true., rigid, pn, [3.0_dp])
      call check(error, abs(pn(1) - 13.0_dp) <= 1e-14_dp .and. abs(res%bearing_n_max(1) - 13.0_dp) <= 1e-14_dp &
                 .and. abs(res%bearing_n_min(1) - 5.0_dp) <= 1e-14_dp, "the overturning's dN added, the extremes")
      if (allocated(error)) return
      call observe_bearing_forces(res, model, 0.02_dp, 0.01_dp, -2.0_dp*g, .false., rigid, pn)
      call observe_bearing_forces(res, model, 0.03_dp, 0.01_dp, -3.0_dp*g, .false., rigid, pn)
      call check(error, res%bearing_uplifts(1) == 1 .and. res%bearing_uplift_first(1) == 0.02_dp .and. &
                 abs(res%bearing_n_min(1) + 20.0_dp) <= 1e-13_dp, "one uplift, from where N first falls to <= 0")
   end subroutine test_bearing_forces

end module test_fd_observer
