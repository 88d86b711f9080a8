!> The observer of a run, one for every technique: it sets up the result, keeps the peaks
!> over every accepted state, samples the history, counts phase transitions and
!> correctness violations, and closes the energy balance. A technique hands it the state
!> (time, table acceleration, u, v, relative acceleration, and per device s, s', F and
!> phase); a new output quantity is a change here (and in the writer), not in the loops.
module fd_observer
   use fd_kinds, only: dp
   use fd_error, only: error_type
   use fd_model, only: model_type, integration_type
   use fd_excitation, only: excitation_type
   use fd_result, only: result_type, init_result, max_violation_times, max_event_times
   use fd_linalg, only: sym_matvec
   use fd_engineering, only: engineering_init, observe_engineering, storey_values, observe_storey_peak
   implicit none
   private

   public :: observer_type, observer_init, sample_due, observe_start, observe_peaks, observe_sample
   public :: observe_transitions, observe_violations, observe_end, strain_energy
   public :: observe_start_energies, observe_end_energies
   public :: observe_peak_value, observe_envelope, observe_event, observe_accumulation
   public :: peak_of_u, peak_of_v, peak_of_aabs, peak_of_s, peak_of_force, peak_of_storey
   public :: observe_storeys

   integer, parameter :: peak_of_u = 1      !! |u| of a DOF
   integer, parameter :: peak_of_v = 2      !! |v| of a DOF
   integer, parameter :: peak_of_aabs = 3   !! |absolute acceleration| of a DOF
   integer, parameter :: peak_of_s = 4      !! |s| of a device
   integer, parameter :: peak_of_force = 5  !! |F| of a device
   integer, parameter :: peak_of_storey = 6 !! |drift|, |V| of a storey, |Vb|: the history's order

   !> What the observer keeps between calls.
   type :: observer_type
      integer :: nsteps = 0          !! dt1 steps of the run
      integer :: every = 1           !! dt1 steps between history rows
      integer :: rows = 0            !! history rows written
      real(dp) :: e_kin0 = 0.0_dp    !! kinetic energy at the start [J]
      real(dp) :: e_str0 = 0.0_dp    !! strain energy at the start [J]
      real(dp) :: e_dev0 = 0.0_dp    !! elastic energy stored in devices at the start [J]
   end type observer_type

contains

   !> Set up the result of a run (history, per-DOF and per-device summary) and the
   !> observer: the number of dt1 steps and the sampling interval.
   subroutine observer_init(model, exc, opts, res, obs, error)
      type(model_type), intent(in) :: model         !! the model run
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(integration_type), intent(in) :: opts    !! integration settings
      type(result_type), intent(inout) :: res       !! the result to set up
      type(observer_type), intent(out) :: obs       !! the observer
      type(error_type), allocatable, intent(out) :: error !! not enough memory

      call init_result(model, exc, opts, res, obs%nsteps, obs%every, error)
      if (allocated(error)) return
      res%technique = opts%technique
      ! names, modes and storeys (res%period_stuck: set by the technique before)
      call engineering_init(model, exc, opts, res%period_stuck, res%eng, error)
   end subroutine observer_init

   !> Whether the history takes a row after dt1 step k (every `every` steps, and the last).
   pure logical function sample_due(obs, k)
      type(observer_type), intent(in) :: obs  !! the observer
      integer, intent(in) :: k                !! dt1 steps done

      sample_due = mod(k, obs%every) == 0 .or. k == obs%nsteps
   end function sample_due

   !> Strain energy of the springs, 1/2 u' K u.
   subroutine strain_energy(k, u, tmp, e)
      real(dp), intent(in) :: k(:, :)      !! springs' stiffness
      real(dp), intent(in) :: u(:)         !! displacements
      real(dp), intent(inout) :: tmp(:)    !! work (n)
      real(dp), intent(out) :: e           !! 1/2 u' K u [J]

      call sym_matvec(k, u, tmp, 1.0_dp, 0.0_dp)
      e = 0.5_dp*dot_product(u, tmp)
   end subroutine strain_energy

   !> Energies of the initial state, from which the balance is counted.
   subroutine observe_start(obs, mass, k, u, v, e_device, tmp)
      type(observer_type), intent(inout) :: obs !! the observer
      real(dp), intent(in) :: mass(:)      !! lumped masses
      real(dp), intent(in) :: k(:, :)      !! springs' stiffness
      real(dp), intent(in) :: u(:)         !! displacements at t = 0
      real(dp), intent(in) :: v(:)         !! velocities at t = 0
      real(dp), intent(in) :: e_device     !! elastic energy stored in devices at t = 0
      real(dp), intent(inout) :: tmp(:)    !! work (n)

      real(dp) :: e

      call strain_energy(k, u, tmp, e)
      call observe_start_energies(obs, 0.5_dp*sum(mass*v**2), e, e_device)
   end subroutine observe_start

   !> Energies of the initial state, given by a technique that computes them itself (without
   !> a dense stiffness matrix).
   pure subroutine observe_start_energies(obs, e_kin, e_str, e_device)
      type(observer_type), intent(inout) :: obs !! the observer
      real(dp), intent(in) :: e_kin        !! kinetic energy at t = 0 [J]
      real(dp), intent(in) :: e_str        !! springs' strain energy at t = 0 [J]
      real(dp), intent(in) :: e_device     !! elastic energy stored in devices at t = 0 [J]

      obs%e_kin0 = e_kin
      obs%e_str0 = e_str
      obs%e_dev0 = e_device
   end subroutine observe_start_energies

   !> Peaks over the accepted states: |u| (and its time), |v|, |absolute acceleration| (and
   !> its time) per DOF, |s| and |F| per device.
   pure subroutine observe_peaks(res, t, u, v, acc, ag, s, force)
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: t                !! time [s]
      real(dp), intent(in) :: u(:)             !! relative displacements [m]
      real(dp), intent(in) :: v(:)             !! relative velocities [m/s]
      real(dp), intent(in) :: acc(:)           !! relative accelerations [m/s2]
      real(dp), intent(in) :: ag               !! table acceleration [m/s2]
      real(dp), intent(in) :: s(:)             !! device relative displacements [m]
      real(dp), intent(in) :: force(:)         !! device forces [N]
      real(dp) :: x
      integer :: i

      do i = 1, size(u)
         if (abs(u(i)) > res%peak_u(i)) then
            res%peak_u(i) = abs(u(i)); res%peak_u_time(i) = t
         end if
         res%peak_v(i) = max(res%peak_v(i), abs(v(i)))
         x = abs(acc(i) + ag)
         if (x > res%peak_aabs(i)) then
            res%peak_aabs(i) = x; res%peak_aabs_time(i) = t
         end if
      end do
      do i = 1, size(s)
         res%peak_s(i) = max(res%peak_s(i), abs(s(i)))
         res%peak_force(i) = max(res%peak_force(i), abs(force(i)))
      end do
      call observe_engineering(res%eng, t, u, v, s, force)
   end subroutine observe_peaks

   !> One value into a peak of the summary (a technique that knows its solution between
   !> steps passes the exact extrema, with their times): quantity peak_of_*, DOF or device i.
   pure subroutine observe_peak_value(res, quantity, i, value, t)
      type(result_type), intent(inout) :: res  !! the result
      integer, intent(in) :: quantity          !! peak_of_u, _v, _aabs, _s, _force, _storey
      integer, intent(in) :: i                 !! DOF, device, or storey quantity (drift1, V1, ..., Vb)
      real(dp), intent(in) :: value            !! |value|
      real(dp), intent(in) :: t                !! its time [s]

      select case (quantity)
      case (peak_of_u)
         if (value > res%peak_u(i)) then
            res%peak_u(i) = value; res%peak_u_time(i) = t
         end if
      case (peak_of_v)
         res%peak_v(i) = max(res%peak_v(i), value)
      case (peak_of_aabs)
         if (value > res%peak_aabs(i)) then
            res%peak_aabs(i) = value; res%peak_aabs_time(i) = t
         end if
      case (peak_of_s)
         res%peak_s(i) = max(res%peak_s(i), value)
      case (peak_of_force)
         res%peak_force(i) = max(res%peak_force(i), value)
      case (peak_of_storey)
         call observe_storey_peak(res%eng, i, value, t)
      end select
   end subroutine observe_peak_value

   !> The storeys at a state the technique reports besides observe_peaks (a row of the exact
   !> technique): drifts, shears, their peaks, and the values kept as the residual ones.
   pure subroutine observe_storeys(res, t, u, v, s, force)
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: t                !! time [s]
      real(dp), intent(in) :: u(:), v(:)       !! relative displacements [m], velocities [m/s]
      real(dp), intent(in) :: s(:), force(:)   !! device relative displacements [m], forces [N]

      call observe_engineering(res%eng, t, u, v, s, force)
   end subroutine observe_storeys

   !> The maxima since the previous row (per DOF |u|, |v|, |aabs|, per device |s|, |F|, per
   !> storey |drift|, |V|, then |Vb|) into the last row written (a history with those
   !> columns, has_envelope).
   pure subroutine observe_envelope(obs, res, env)
      type(observer_type), intent(in) :: obs   !! the observer
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: env(:)           !! the maxima, in the columns' order

      if (res%env_col == 0 .or. obs%rows > res%nout .or. obs%rows < 1) return
      res%hist(res%env_col:res%env_col + size(env) - 1, obs%rows) = env
   end subroutine observe_envelope

   !> An event at time t (phases changed): its time is kept (the first max_event_times).
   pure subroutine observe_event(res, t)
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: t                !! time of the event [s]

      if (res%n_event_times >= max_event_times) return
      res%n_event_times = res%n_event_times + 1
      res%event_time(res%n_event_times) = t
   end subroutine observe_event

   !> An accumulation point of events (a Zeno sequence) at time t, ended by sticking.
   pure subroutine observe_accumulation(res, t)
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: t                !! its time [s]

      res%accumulations = res%accumulations + 1
      if (res%n_accumulation_times >= max_violation_times) return
      res%n_accumulation_times = res%n_accumulation_times + 1
      res%accumulation_time(res%n_accumulation_times) = t
   end subroutine observe_accumulation

   !> The next row of the history: t, ag, (u, v, aabs) per DOF, (s, s', F, phase) per device.
   pure subroutine observe_sample(obs, res, t, ag, u, v, acc, s, sd, force, phase)
      type(observer_type), intent(inout) :: obs !! the observer
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: t                !! time [s]
      real(dp), intent(in) :: ag               !! table acceleration [m/s2]
      real(dp), intent(in) :: u(:)             !! relative displacements [m]
      real(dp), intent(in) :: v(:)             !! relative velocities [m/s]
      real(dp), intent(in) :: acc(:)           !! relative accelerations [m/s2]
      real(dp), intent(in) :: s(:)             !! device relative displacements [m]
      real(dp), intent(in) :: sd(:)            !! device relative velocities [m/s]
      real(dp), intent(in) :: force(:)         !! device forces [N]
      integer, intent(in) :: phase(:)          !! device phases (0 stick, +-1 slip)
      integer :: i, c

      obs%rows = obs%rows + 1
      if (obs%rows > res%nout) return
      associate (row => obs%rows)
         res%hist(1, row) = t
         res%hist(2, row) = ag
         c = 2
         do i = 1, size(u)
            res%hist(c + 1:c + 3, row) = [u(i), v(i), acc(i) + ag]
            c = c + 3
         end do
         do i = 1, size(s)
            res%hist(c + 1:c + 4, row) = [s(i), sd(i), force(i), real(phase(i), dp)]
            c = c + 4
         end do
         ! storeys: (drift, V) each, then the base shear
         if (res%eng%n_storeys > 0) then
            i = res%eng%n_storeys
            call storey_values(res%eng, u, v, force, res%hist(c + 1:c + 2*i - 1:2, row), &
                               res%hist(c + 2:c + 2*i:2, row), res%hist(c + 2*i + 1, row))
         end if
      end associate
   end subroutine observe_sample

   !> Count the phase changes of the devices: stick to slip, slip to stick, and slip
   !> reversals (slip + to slip - and back without sticking).
   pure subroutine observe_transitions(res, old, new)
      type(result_type), intent(inout) :: res  !! the result
      integer, intent(in) :: old(:)            !! phases before (0 stick, +-1 slip)
      integer, intent(in) :: new(:)            !! phases after

      integer :: d

      do d = 1, size(old)
         if (old(d) == new(d)) cycle
         if (old(d) == 0) then
            res%stick_to_slip(d) = res%stick_to_slip(d) + 1
         else if (new(d) == 0) then
            res%slip_to_stick(d) = res%slip_to_stick(d) + 1
         else
            res%reversals(d) = res%reversals(d) + 1
         end if
      end do
   end subroutine observe_transitions

   !> Count the devices that violate the correctness condition (eqs. 9, 12) in a step
   !> accepted at time t, and keep the first times and devices.
   pure subroutine observe_violations(res, t, ok)
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: t                !! end of the step [s]
      logical, intent(in) :: ok(:)             !! per device: the step satisfies the condition
      integer :: d

      do d = 1, size(ok)
         if (ok(d)) cycle
         res%violations = res%violations + 1
         if (res%n_violation_times < max_violation_times) then
            res%n_violation_times = res%n_violation_times + 1
            res%violation_time(res%n_violation_times) = t
            res%violation_device(res%n_violation_times) = d
         end if
      end do
   end subroutine observe_violations

   !> Close the energy balance at the end of the run: kinetic, strain and device elastic
   !> energy (end minus start), friction dissipation (device work minus stored energy) and
   !> the residual input - (kinetic + strain + viscous + friction + device elastic). The
   !> technique has accumulated the input and viscous work in res.
   subroutine observe_end(obs, res, mass, k, u, v, e_device, w_device, tmp)
      type(observer_type), intent(in) :: obs   !! the observer
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: mass(:)          !! lumped masses
      real(dp), intent(in) :: k(:, :)          !! springs' stiffness
      real(dp), intent(in) :: u(:)             !! displacements at the end
      real(dp), intent(in) :: v(:)             !! velocities at the end
      real(dp), intent(in) :: e_device         !! elastic energy stored in devices at the end [J]
      real(dp), intent(in) :: w_device         !! work of the device forces over the run [J]
      real(dp), intent(inout) :: tmp(:)        !! work (n)
      real(dp) :: e

      call strain_energy(k, u, tmp, e)
      call observe_end_energies(obs, res, 0.5_dp*sum(mass*v**2), e, e_device, w_device)
   end subroutine observe_end

   !> Close the energy balance from the end energies a technique computed itself (see
   !> observe_end).
   pure subroutine observe_end_energies(obs, res, e_kin, e_str, e_device, w_device)
      type(observer_type), intent(in) :: obs   !! the observer
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: e_kin            !! kinetic energy at the end [J]
      real(dp), intent(in) :: e_str            !! springs' strain energy at the end [J]
      real(dp), intent(in) :: e_device         !! elastic energy stored in devices at the end [J]
      real(dp), intent(in) :: w_device         !! work of the device forces over the run [J]

      res%e_kinetic = e_kin - obs%e_kin0
      res%e_strain = e_str - obs%e_str0
      res%e_device = e_device - obs%e_dev0
      res%e_friction = w_device - res%e_device
      res%e_residual = res%e_input - (res%e_kinetic + res%e_strain + res%e_viscous + &
                                      res%e_friction + res%e_device)
   end subroutine observe_end_energies

end module fd_observer
