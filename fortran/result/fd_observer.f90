!> The observer of a run, one for every technique, and the only writer of the result's
!> histories, peaks and energies: it sets up the result, keeps the peaks over every accepted
!> state, samples the history, counts phase transitions and correctness violations, and
!> closes the energy balance. A technique hands it the state (observe_peaks: the
!> observed_state its workspace extends; observe_sample: time, table acceleration, u, v,
!> relative acceleration, and per device s, s', F and phase), the planar bearings' normal
!> forces (observe_bearing_forces), the work of each step (observe_work) and of each device's
!> force with the device's slip travel (observe_device_motion, or added into the observer's
!> device_work and slip_travel in the technique's own loop over the devices), and, when it
!> knows its solution between steps, the exact extrema (observe_extrema, observe_extremum);
!> the stuck system's period it computed is an argument of observer_init. A new output
!> quantity is a change here (and in the writer), not in the loops.
!>
!> A run's control (fd_run_control), when the technique is given one, says which history
!> columns are kept and where their rows go (the result, the caller's buffer, a file written
!> as the run goes), and asks to stop: the technique calls observe_poll after every accepted
!> step, and returns the error of observe_stop_error when it says stop. Polls cost a counter
!> decrement; every few milliseconds of wall clock a poll reads the stop request, publishes
!> the time reached and calls the progress callback when its interval has passed.
module fd_observer
   use, intrinsic :: iso_fortran_env, only: int64
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_real
   use fd_model, only: model_type, integration_type
   use fd_excitation, only: excitation_type, excitation_record
   use fd_result, only: result_type, init_result, max_violation_times
   use fd_linalg, only: sym_matvec
   use fd_run_control, only: run_control, cancel_requested, stat_cancelled
   use fd_result, only: history_header
   use fd_friction_planar, only: normal_force
   use fd_vertical_support, only: vertical_support, supported_normal_forces
   use fd_engineering, only: engineering_init, observe_engineering, storey_values, observe_storey_peak, &
                             observe_floor_accelerations
   implicit none
   private

   public :: observer_type, observed_state, observer_init, sample_due, observe_start, observe_peaks, observe_sample
   public :: observe_transitions, observe_violations, observe_end, strain_energy
   public :: observe_start_energies, observe_end_energies, observe_poll, observe_stop_error
   public :: observe_extrema, observe_extremum, observe_work, observe_device_motion
   public :: observe_storeys, observe_normal_forces, observe_flights, observe_bearing_forces

   !> Wall-clock time aimed at between two polls that look at the clock [s].
   real(dp), parameter :: poll_target = 0.01_dp

   !> The state of the structure a technique hands the observer at an accepted step (observe_peaks):
   !> its workspace extends this type, so that the observer reads the technique's own arrays
   !> through one argument (no copy, no array descriptor built a step).
   type :: observed_state
      integer :: n = 0                        !! DOFs
      integer :: nd = 0                       !! devices
      real(dp) :: ag = 0.0_dp                 !! table acceleration [m/s2]
      real(dp) :: ag2 = 0.0_dp                !! a second component's table acceleration (0: none) [m/s2]
      real(dp), allocatable :: u(:)           !! (n) relative displacements [m]
      real(dp), allocatable :: v(:)           !! (n) relative velocities [m/s]
      real(dp), allocatable :: a(:)           !! (n) relative accelerations [m/s2]
      real(dp), allocatable :: s(:)           !! (nd) device relative displacements [m]
      real(dp), allocatable :: f(:)           !! (nd) device forces [N]
   end type observed_state

   !> What the observer keeps between calls.
   type :: observer_type
      integer :: nsteps = 0          !! dt1 steps of the run
      integer :: every = 1           !! dt1 steps between history rows
      integer :: rows = 0            !! history rows written
      real(dp) :: e_kin0 = 0.0_dp    !! kinetic energy at the start [J]
      real(dp) :: e_str0 = 0.0_dp    !! strain energy at the start [J]
      real(dp) :: e_dev0 = 0.0_dp    !! elastic energy stored in devices at the start [J]
      real(dp), allocatable :: e_dev0_each(:) !! the same, per device [J]
      !> per device, the work of its force over its relative motion [J] and its slip travel (the
      !> integral of |ds| while it slides) [m] so far: added by observe_device_motion, or by the
      !> technique's own loop over the devices where a call a step would cost a share of the
      !> step (Newmark's device_step: 2-3 % of a step of the paper's model, callgrind)
      real(dp), allocatable :: device_work(:), slip_travel(:)
      type(run_control), pointer :: ctl => null() !! the run's control, if any
      integer, allocatable :: dofs(:)     !! DOFs in the history
      integer, allocatable :: devices(:)  !! devices in the history
      logical :: all_columns = .true.     !! every DOF and device in the history
      real(dp), allocatable :: row(:)     !! the row being formed
      logical :: to_result = .true.       !! rows into res%hist
      integer :: countdown = 1            !! polls until the next look at the clock
      integer :: poll_every = 1           !! polls between looks at the clock
      integer(int64) :: last_poll = 0     !! clock count of the last look
      integer(int64) :: last_report = 0   !! clock count of the last progress report
      integer(int64) :: rate = 1          !! clock counts a second
      logical :: stopped = .false.        !! a poll said stop
      real(dp) :: stop_time = 0.0_dp      !! time reached when it did [s]
   end type observer_type

contains

   !> Set up the result of a run (history, per-DOF and per-device summary) and the
   !> observer: the number of dt1 steps and the sampling interval. With a control: the
   !> history's columns and destinations it selects, and its row sink begun (for the history
   !> file: created under its temporary name, the header written).
   subroutine observer_init(model, exc, opts, period_stuck, res, obs, error, ctl)
      type(model_type), intent(in) :: model         !! the model run
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(integration_type), intent(in) :: opts    !! integration settings
      real(dp), intent(in) :: period_stuck          !! first period of the stuck system, as the
                                                    !! technique computed it [s] (0: none)
      type(result_type), intent(inout) :: res       !! the result to set up
      type(observer_type), intent(out) :: obs       !! the observer
      type(error_type), allocatable, intent(out) :: error !! not enough memory, history file
      type(run_control), intent(inout), target, optional :: ctl !! the run's control
      character(len=:), allocatable :: header
      integer :: i, rows

      if (present(ctl)) then
         obs%ctl => ctl
         obs%all_columns = ctl%select_all
         obs%to_result = ctl%keep .and. .not. associated(ctl%buffer)
      end if
      if (obs%all_columns) then
         obs%dofs = [(i, i=1, model%n_dof)]
         obs%devices = [(i, i=1, model%n_devices)]
      else
         obs%dofs = ctl%dofs
         obs%devices = ctl%devices
      end if
      call init_result(model, exc, opts, res, obs%nsteps, obs%every, error, obs%dofs, obs%devices, obs%to_result)
      if (allocated(error)) return
      res%technique = opts%technique
      if (exc%kind == excitation_record .and. allocated(exc%acc)) then
         if (size(exc%acc) > 0) res%record_pga = maxval(abs(exc%acc))
      end if
      ! names, modes and storeys
      call engineering_init(model, exc, opts, period_stuck, res%eng, error)
      if (allocated(error)) return
      allocate (obs%row(res%ncol), obs%e_dev0_each(model%n_devices), obs%device_work(model%n_devices), &
                obs%slip_travel(model%n_devices))
      obs%row = 0.0_dp
      obs%e_dev0_each = 0.0_dp
      obs%device_work = 0.0_dp
      obs%slip_travel = 0.0_dp
      if (.not. associated(obs%ctl)) return
      ctl%duration = obs%nsteps*(exc%dt_record/opts%n1)
      ctl%time = 0.0_dp
      if (associated(ctl%buffer)) then
         rows = size(ctl%buffer, 2)
         if (size(ctl%buffer, 1) /= res%ncol .or. rows /= res%nout) then
            call fatal_error(error, "the history buffer has the wrong shape")
            return
         end if
      end if
      if (allocated(ctl%sink)) then
         call history_header(res, header)
         call ctl%sink%begin(header, res%ncol, error)
         if (allocated(error)) return
      end if
      call system_clock(obs%last_poll, obs%rate)
      obs%last_report = obs%last_poll
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
   !> a dense stiffness matrix); with devices that store energy, each one's share.
   pure subroutine observe_start_energies(obs, e_kin, e_str, e_device, e_each)
      type(observer_type), intent(inout) :: obs !! the observer
      real(dp), intent(in) :: e_kin        !! kinetic energy at t = 0 [J]
      real(dp), intent(in) :: e_str        !! springs' strain energy at t = 0 [J]
      real(dp), intent(in) :: e_device     !! elastic energy stored in devices at t = 0 [J]
      real(dp), intent(in), optional :: e_each(:) !! the same per device (default 0) [J]

      obs%e_kin0 = e_kin
      obs%e_str0 = e_str
      obs%e_dev0 = e_device
      if (present(e_each)) obs%e_dev0_each = e_each
   end subroutine observe_start_energies

   !> Peaks over the accepted states: |u| (and its time), |v|, |absolute acceleration| (and
   !> its time) per DOF, |s| and |F| per device (and s as its residual displacement); the
   !> planar bearings', the floors' and the storeys' (fd_engineering) at the state x at time t.
   pure subroutine observe_peaks(res, t, x)
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: t                !! time [s]
      type(observed_state), intent(in) :: x    !! the state
      real(dp) :: y, ri
      integer :: i
      logical :: has_r, has_r2

      has_r = allocated(res%eng%r)
      has_r2 = allocated(res%eng%r2)
      if (.not. (has_r .or. has_r2)) then
         ! every DOF along the table motion (r_i = 1), one component (the paper's models): one
         ! loop over the DOFs
         call dof_peaks(x%n, t, x%ag, x%u, x%v, x%a, res%peak_u, res%peak_u_time, res%peak_v, res%peak_aabs, &
                        res%peak_aabs_time)
      else
         do i = 1, x%n
            call motion_peak(t, x%u(i), x%v(i), res%peak_u(i), res%peak_u_time(i), res%peak_v(i))
            ! the absolute acceleration: the table's along the DOF's direction r_i added
            ri = 1.0_dp
            if (has_r) ri = res%eng%r(i)
            y = x%a(i) + ri*x%ag
            if (has_r2) y = y + res%eng%r2(i)*x%ag2
            y = abs(y)
            if (y > res%peak_aabs(i)) then
               res%peak_aabs(i) = y; res%peak_aabs_time(i) = t
            end if
         end do
      end if
      call device_peaks(x%nd, x%s, x%f, res%peak_s, res%peak_force, res%eng%residual_s)
      if (res%n_bearings > 0) call observe_bearings(res, t, x%nd, x%s, x%f)
      if (res%eng%n_floors > 0) call observe_floor_accelerations(res%eng, t, x%n, x%a, x%ag, x%ag2)
      ! last: the compiler makes it a jump (a tail call), no return through this routine
      call observe_engineering(res%eng, t, x%n, x%nd, x%u, x%v, x%f)
   end subroutine observe_peaks

   ! The kernels of observe_peaks take their arrays with explicit shapes: the compiler then
   ! knows that the peaks written alias none of the state's arrays and keeps every address in
   ! a register (through the result's and the state's components it reloads them after each
   ! store: observe_peaks cost a third more on the paper's two-mass model, callgrind).

   !> One DOF's peaks of |u| (and its time) and of |v| at time t.
   pure subroutine motion_peak(t, u, v, peak_u, peak_u_time, peak_v)
      real(dp), intent(in) :: t                    !! time [s]
      real(dp), intent(in) :: u, v                 !! the state [m, m/s]
      real(dp), intent(inout) :: peak_u, peak_u_time, peak_v !! [m, s, m/s]

      if (abs(u) > peak_u) then
         peak_u = abs(u); peak_u_time = t
      end if
      peak_v = max(peak_v, abs(v))
   end subroutine motion_peak

   !> The peaks of |u| (and their times) and of |v| of n DOFs (motion_peak), and of the absolute
   !> acceleration |a + ag| (and their times) along the one table motion, at time t.
   pure subroutine dof_peaks(n, t, ag, u, v, a, peak_u, peak_u_time, peak_v, peak_aabs, peak_aabs_time)
      integer, intent(in) :: n                     !! DOFs
      real(dp), intent(in) :: t                    !! time [s]
      real(dp), intent(in) :: ag                   !! table acceleration [m/s2]
      real(dp), intent(in) :: u(n), v(n), a(n)     !! the state [m, m/s, m/s2]
      real(dp), intent(inout) :: peak_u(n), peak_u_time(n), peak_v(n) !! [m, s, m/s]
      real(dp), intent(inout) :: peak_aabs(n), peak_aabs_time(n)      !! [m/s2, s]
      real(dp) :: y
      integer :: i

      do i = 1, n
         call motion_peak(t, u(i), v(i), peak_u(i), peak_u_time(i), peak_v(i))
         y = abs(a(i) + ag)
         if (y > peak_aabs(i)) then
            peak_aabs(i) = y; peak_aabs_time(i) = t
         end if
      end do
   end subroutine dof_peaks

   !> The peaks of |s| and |F| of nd devices, and s as the residual displacement (that of
   !> the last state observed).
   pure subroutine device_peaks(nd, s, f, peak_s, peak_f, residual_s)
      integer, intent(in) :: nd                    !! devices
      real(dp), intent(in) :: s(nd), f(nd)         !! relative displacements [m], forces [N]
      real(dp), intent(inout) :: peak_s(nd), peak_f(nd) !! [m, N]
      real(dp), intent(out) :: residual_s(nd)      !! [m]
      integer :: i

      do i = 1, nd
         peak_s(i) = max(peak_s(i), abs(s(i)))
         peak_f(i) = max(peak_f(i), abs(f(i)))
         residual_s(i) = s(i)
      end do
   end subroutine device_peaks

   !> The planar bearings' resultant displacement |(s_x, s_y)|: its peak, the peak's direction
   !> and time, and the last value observed (the residual at the run's end); each bearing's
   !> travel (the chord |(ds_x, ds_y)| of every accepted step it slid in: at its start, at its
   !> end or in a phase it was taken in) and the turns of its sliding
   !> direction (bearing_turns); the isolation shear, the bearings' forces summed along x and
   !> y: friction F plus the pendulum's restoring (p / R) s of each component.
   pure subroutine observe_bearings(res, t, nd, s, force)
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: t                !! time [s]
      integer, intent(in) :: nd                !! devices
      real(dp), intent(in) :: s(nd)            !! device relative displacements [m]
      real(dp), intent(in) :: force(nd)        !! device forces [N]
      real(dp), parameter :: deg = 180.0_dp/acos(-1.0_dp)
      real(dp) :: sx, sy, r, fx, fy, v(3)
      integer :: b, k

      v = 0.0_dp
      do b = 1, res%n_bearings
         sx = s(res%bearing_dev(1, b))
         sy = s(res%bearing_dev(2, b))
         if (res%bearing_seen .and. (res%bearing_slid(b) .or. res%bearing_sliding(b))) &
            res%bearing_travel(b) = res%bearing_travel(b) + hypot(sx - res%bearing_last(1, b), sy - res%bearing_last(2, b))
         res%bearing_slid(b) = res%bearing_sliding(b)
         res%bearing_last(:, b) = [sx, sy]
         r = hypot(sx, sy)
         if (r > res%bearing_peak(b)) then
            res%bearing_peak(b) = r
            res%bearing_peak_angle(b) = atan2(sy, sx)*deg
            res%bearing_peak_time(b) = t
         end if
         fx = force(res%bearing_dev(1, b))
         fy = force(res%bearing_dev(2, b))
         if (res%bearing_sliding(b)) call bearing_turns(res, b, fx, fy)
         v(1) = v(1) + fx + res%bearing_k(b)*sx
         v(2) = v(2) + fy + res%bearing_k(b)*sy
      end do
      res%bearing_seen = .true.
      v(3) = hypot(v(1), v(2))
      v(1:2) = abs(v(1:2))
      do k = 1, 3
         if (v(k) > res%peak_iso_shear(k)) then
            res%peak_iso_shear(k) = v(k)
            res%peak_iso_shear_time(k) = t
         end if
      end do
   end subroutine observe_bearings

   !> A sliding bearing's reversals: the signed angle its friction force (fx, fy) turned since
   !> the last sliding step observed is added to its turn since the slide's start; each 180
   !> degrees turned either way is a reversal (the turn keeps what exceeds them). Back
   !> and forth along a line each turn back is one (the 1D slip_reversals); a circular orbit
   !> makes two a revolution.
   pure subroutine bearing_turns(res, b, fx, fy)
      type(result_type), intent(inout) :: res  !! the result
      integer, intent(in) :: b                 !! the bearing
      real(dp), intent(in) :: fx, fy           !! its components' friction forces [N]
      real(dp), parameter :: pi = acos(-1.0_dp)
      real(dp) :: px, py

      if (fx == 0.0_dp .and. fy == 0.0_dp) return
      px = res%bearing_dir(1, b)
      py = res%bearing_dir(2, b)
      res%bearing_dir(:, b) = [fx, fy]
      if (px == 0.0_dp .and. py == 0.0_dp) return   ! the slide's first direction
      res%bearing_turn(b) = res%bearing_turn(b) + atan2(px*fy - py*fx, px*fx + py*fy)
      if (abs(res%bearing_turn(b)) >= pi) then
         res%bearing_reversals(b) = res%bearing_reversals(b) + 1
         res%bearing_turn(b) = res%bearing_turn(b) - sign(pi, res%bearing_turn(b))
      end if
   end subroutine bearing_turns

   !> A bearing starts or stops sliding (its x component's phase leaves or enters stick): a
   !> slide's direction and turn start again; a step taken sliding counts in its travel.
   pure subroutine bearing_phases(res, old, new)
      type(result_type), intent(inout) :: res  !! the result
      integer, intent(in) :: old(:)            !! phases before (0 stick, +-1 slip)
      integer, intent(in) :: new(:)            !! phases after
      integer :: b, d

      do b = 1, res%n_bearings
         d = res%bearing_dev(1, b)
         if (new(d) /= 0) res%bearing_slid(b) = .true.
         if ((old(d) == 0) .eqv. (new(d) == 0)) cycle
         res%bearing_sliding(b) = new(d) /= 0
         res%bearing_dir(:, b) = 0.0_dp
         res%bearing_turn(b) = 0.0_dp
      end do
   end subroutine bearing_phases
   !> The planar bearings' normal forces N at t (a vertical component): their extremes, and
   !> uplift (N <= 0): an episode starts where N falls to <= 0 (at t = 0 when it starts so),
   !> and the steps that start lifted (which carry no friction, no restoring force) add their
   !> length h to the time spent lifted.
   pure subroutine observe_normal_forces(res, t, h, pn)
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: t                !! time [s]
      real(dp), intent(in) :: h                !! the step that reached t (0: the start) [s]
      real(dp), intent(in) :: pn(:)            !! N of each bearing at t [N]
      integer :: b

      do b = 1, res%n_bearings
         if (h > 0.0_dp .and. .not. res%bearing_n_last(b) > 0.0_dp) &
            res%bearing_uplift_time(b) = res%bearing_uplift_time(b) + h
         if (.not. pn(b) > 0.0_dp .and. (h == 0.0_dp .or. res%bearing_n_last(b) > 0.0_dp)) then
            res%bearing_uplifts(b) = res%bearing_uplifts(b) + 1
            if (res%bearing_uplifts(b) == 1) res%bearing_uplift_first(b) = t
         end if
         if (h == 0.0_dp) then
            res%bearing_n_min(b) = pn(b)
            res%bearing_n_max(b) = pn(b)
         end if
         res%bearing_n_min(b) = min(res%bearing_n_min(b), pn(b))
         res%bearing_n_max(b) = max(res%bearing_n_max(b), pn(b))
         res%bearing_n_last(b) = pn(b)
      end do
   end subroutine observe_normal_forces

   !> The planar bearings' normal forces at the accepted time t, into pn and the observer
   !> (observe_normal_forces: extremes and uplift): N = N0 (1 + az / g) plus the overturning's
   !> dN of the state (tilt), on an elastic vertical support its oscillator's (vs), with the
   !> supports' flights (observe_flights); h the step that reached t (0 at the start).
   subroutine observe_bearing_forces(res, model, t, h, az, tilt, vs, pn, dn)
      type(result_type), intent(inout) :: res  !! the result
      type(model_type), intent(in) :: model    !! the model (its bearings' devices)
      real(dp), intent(in) :: t                !! time [s]
      real(dp), intent(in) :: h                !! the step that reached t (0: the start) [s]
      real(dp), intent(in) :: az               !! vertical table acceleration at t [m/s2]
      logical, intent(in) :: tilt              !! the overturning's dN is added
      type(vertical_support), intent(in) :: vs !! the elastic vertical supports (none: nb = 0)
      real(dp), intent(inout) :: pn(:)         !! work: N of each bearing [N]
      real(dp), intent(in), optional :: dn(:)  !! the overturning's dN of each bearing (tilt) [N]
      integer :: b

      do b = 1, res%n_bearings
         if (tilt) then
            pn(b) = normal_force(model%dev(res%bearing_dev(1, b)), az, dn(b))
         else
            pn(b) = normal_force(model%dev(res%bearing_dev(1, b)), az)
         end if
      end do
      ! (the supports' arrays exist only for a model with elastic supports; an absent dn is
      ! not handed on: gfortran reads the bounds of an absent assumed-shape argument passed on)
      if (vs%nb > 0) then
         if (present(dn)) then
            call supported_normal_forces(vs, tilt, pn, dn)
         else
            call supported_normal_forces(vs, tilt, pn)
         end if
      end if
      call observe_normal_forces(res, t, h, pn)
      ! the supports' flights, located within the steps (with the overturning, whose dN may
      ! unload a bearing in contact, its uplift is counted by the steps as on a rigid support)
      if (vs%nb > 0) call observe_flights(res, vs%bearing, vs%gap, vs%flights, vs%first, vs%air, .not. tilt)
   end subroutine observe_bearing_forces

   !> The bearings on elastic supports: each one's peak uplift so far and, where the supports
   !> locate their flights within the steps (located), its lift-offs, the first one's time and
   !> its time in flight (otherwise, as with the overturning, uplift is counted by the steps).
   pure subroutine observe_flights(res, bearing, gap, flights, first, air, located)
      type(result_type), intent(inout) :: res  !! the result
      integer, intent(in) :: bearing(:)        !! (supports) each one's bearing
      real(dp), intent(in) :: gap(:)           !! its peak uplift so far [m]
      integer, intent(in) :: flights(:)        !! its lift-offs so far
      real(dp), intent(in) :: first(:)         !! the first one's time [s]
      real(dp), intent(in) :: air(:)           !! its time in flight so far [s]
      logical, intent(in) :: located           !! the flights are the supports' own
      integer :: i, b

      do i = 1, size(bearing)
         b = bearing(i)
         if (allocated(res%bearing_uplift_peak)) res%bearing_uplift_peak(b) = max(res%bearing_uplift_peak(b), gap(i))
         if (.not. located) cycle
         res%bearing_uplifts(b) = flights(i)
         res%bearing_uplift_first(b) = first(i)
         res%bearing_uplift_time(b) = air(i)
      end do
   end subroutine observe_flights

   !> The exact extrema of a technique that knows its solution between steps: |y(q)| of every
   !> output quantity q at time t into the summary's peaks (observe_extremum's order).
   pure subroutine observe_extrema(res, y, t)
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: y(:)             !! the quantities' values, in observe_extremum's order
      real(dp), intent(in) :: t                !! their time [s]
      integer :: q

      do q = 1, size(y)
         call observe_extremum(res, q, abs(y(q)), t)
      end do
   end subroutine observe_extrema

   !> One exact extremum |value| at time t of output quantity q, numbered as the history's
   !> envelope columns of every DOF and device: |u|, |v|, |aabs| of DOF i are q = 3 i - 2,
   !> 3 i - 1, 3 i; |s|, |F| of device d are q = 3 n + 2 d - 1, 3 n + 2 d; then the storeys'
   !> |drift1|, |V1|, ..., |Vb| (fd_engineering's order).
   pure subroutine observe_extremum(res, q, value, t)
      type(result_type), intent(inout) :: res  !! the result
      integer, intent(in) :: q                 !! the quantity
      real(dp), intent(in) :: value            !! |value|
      real(dp), intent(in) :: t                !! its time [s]
      integer :: i, n3

      n3 = 3*res%n_dof
      if (q > n3 + 2*res%n_devices) then
         call observe_storey_peak(res%eng, q - n3 - 2*res%n_devices, value, t)
      else if (q <= n3) then
         i = (q + 2)/3
         select case (q - 3*(i - 1))
         case (1)
            if (value > res%peak_u(i)) then
               res%peak_u(i) = value; res%peak_u_time(i) = t
            end if
         case (2)
            res%peak_v(i) = max(res%peak_v(i), value)
         case default
            if (value > res%peak_aabs(i)) then
               res%peak_aabs(i) = value; res%peak_aabs_time(i) = t
            end if
         end select
      else
         i = (q - n3 + 1)/2
         if (mod(q - n3, 2) == 1) then
            res%peak_s(i) = max(res%peak_s(i), value)
         else
            res%peak_force(i) = max(res%peak_force(i), value)
         end if
      end if
   end subroutine observe_extremum

   !> The work of a step (or part of one): the table's inertia loads' work `input` and the
   !> viscous dissipation `viscous` [J] into the energy balance (observe_end closes it).
   pure subroutine observe_work(res, input, viscous)
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: input            !! work of the table's inertia loads [J]
      real(dp), intent(in) :: viscous          !! viscous dissipation [J]

      res%e_input = res%e_input + input
      res%e_input_gross = res%e_input_gross + abs(input)
      res%e_viscous = res%e_viscous + viscous
   end subroutine observe_work

   !> The work of device d's force over a step (or part of one) [J] and its slip travel in it
   !> (|ds| while it slid) [m] into the device's totals.
   pure subroutine observe_device_motion(obs, d, work, travel)
      type(observer_type), intent(inout) :: obs !! the observer
      integer, intent(in) :: d                 !! the device
      real(dp), intent(in) :: work             !! work of its force [J]
      real(dp), intent(in) :: travel           !! its slip travel [m]

      obs%device_work(d) = obs%device_work(d) + work
      obs%slip_travel(d) = obs%slip_travel(d) + travel
   end subroutine observe_device_motion

   !> The storeys at a state the technique reports besides observe_peaks (a row of the exact
   !> technique): drifts, shears, their peaks, and the values kept as the residual ones.
   pure subroutine observe_storeys(res, t, u, v, s, force)
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: t                !! time [s]
      real(dp), intent(in) :: u(:), v(:)       !! relative displacements [m], velocities [m/s]
      real(dp), intent(in) :: s(:), force(:)   !! device relative displacements [m], forces [N]

      res%eng%residual_s = s
      call observe_engineering(res%eng, t, size(u), size(s), u, v, force)
   end subroutine observe_storeys

   !> The next row of the history: t, ag, (u, v, aabs) per kept DOF, (s, s', F, phase) per
   !> kept device, then (a history with those columns, has_envelope) the maxima since the
   !> previous row `env` of the kept DOFs and devices; into the result, the control's buffer
   !> and its row sink as selected. The first value not finite of a row that goes only to
   !> the buffer or the sink is noted in the control (run_config_solve makes it an error; the
   !> result's rows are checked at the end). Allocates nothing.
   subroutine observe_sample(obs, res, t, ag, u, v, acc, s, sd, force, phase, env, ag2)
      type(observer_type), intent(inout) :: obs !! the observer
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: t                !! time [s]
      real(dp), intent(in) :: ag               !! table acceleration [m/s2]
      real(dp), intent(in), optional :: ag2    !! a second component's table acceleration [m/s2]
      real(dp), intent(in) :: u(:)             !! relative displacements [m]
      real(dp), intent(in) :: v(:)             !! relative velocities [m/s]
      real(dp), intent(in) :: acc(:)           !! relative accelerations [m/s2]
      real(dp), intent(in) :: s(:)             !! device relative displacements [m]
      real(dp), intent(in) :: sd(:)            !! device relative velocities [m/s]
      real(dp), intent(in) :: force(:)         !! device forces [N]
      integer, intent(in) :: phase(:)          !! device phases (0 stick, +-1 slip)
      real(dp), intent(in), optional :: env(:) !! maxima since the previous row: (|u|, |v|, |aabs|)
                                               !! per DOF, (|s|, |F|) per device (all of them), then
                                               !! (|drift|, |V|) per storey and |Vb| when storeys
      integer :: i, j, c, nq

      obs%rows = obs%rows + 1
      if (obs%rows > res%nout) return
      ! the first row is the state at t = 0: a device sliding in it begins a slip excursion
      if (obs%rows == 1 .and. allocated(res%slip_excursions)) then
         do i = 1, min(size(phase), size(res%slip_excursions))
            if (phase(i) /= 0) res%slip_excursions(i) = res%slip_excursions(i) + 1
         end do
         ! and a bearing sliding in it begins sliding
         do i = 1, res%n_bearings
            res%bearing_sliding(i) = phase(res%bearing_dev(1, i)) /= 0
            res%bearing_slid(i) = res%bearing_sliding(i)
         end do
      end if
      associate (row => obs%row)
         row(1) = t
         row(2) = ag
         c = 2
         if (obs%all_columns) then
            do i = 1, size(u)
               row(c + 1) = u(i); row(c + 2) = v(i); row(c + 3) = acc(i) + table_along(i)
               c = c + 3
            end do
            do i = 1, size(s)
               row(c + 1) = s(i); row(c + 2) = sd(i); row(c + 3) = force(i); row(c + 4) = real(phase(i), dp)
               c = c + 4
            end do
         else
            do j = 1, size(obs%dofs)
               i = obs%dofs(j)
               row(c + 1) = u(i); row(c + 2) = v(i); row(c + 3) = acc(i) + table_along(i)
               c = c + 3
            end do
            do j = 1, size(obs%devices)
               i = obs%devices(j)
               row(c + 1) = s(i); row(c + 2) = sd(i); row(c + 3) = force(i); row(c + 4) = real(phase(i), dp)
               c = c + 4
            end do
         end if
         ! storeys (always, whatever the selection): (drift, V) each, then the base shear
         if (res%eng%n_storeys > 0) then
            i = res%eng%n_storeys
            call storey_values(res%eng, u, v, force, row(c + 1:c + 2*i - 1:2), row(c + 2:c + 2*i:2), &
                               row(c + 2*i + 1))
            c = c + 2*i + 1
         end if
         ! each planar bearing's normal force at the state (observe_normal_forces'; p when constant)
         do i = 1, res%n_bearings
            row(c + i) = res%bearing_n_last(i)
         end do
         c = c + res%n_bearings
         if (present(env) .and. res%env_col > 0) then
            nq = 3*size(u)
            if (obs%all_columns) then
               row(c + 1:c + size(env)) = env
            else
               do j = 1, size(obs%dofs)
                  i = obs%dofs(j)
                  row(c + 1:c + 3) = env(3*i - 2:3*i)
                  c = c + 3
               end do
               do j = 1, size(obs%devices)
                  i = obs%devices(j)
                  row(c + 1:c + 2) = env(nq + 2*i - 1:nq + 2*i)
                  c = c + 2
               end do
               ! the storeys' maxima, after the devices'
               nq = nq + 2*size(s)
               row(c + 1:c + size(env) - nq) = env(nq + 1:)
            end if
         end if
         if (obs%to_result) then
            res%hist(:, obs%rows) = row
         else if (associated(obs%ctl)) then
            if (obs%ctl%bad_column == 0) then
               do i = 1, size(row)
                  if (ieee_is_finite(row(i))) cycle
                  obs%ctl%bad_column = i
                  obs%ctl%bad_time = t
                  obs%ctl%bad_value = row(i)
                  exit
               end do
            end if
         end if
         if (associated(obs%ctl)) then
            if (associated(obs%ctl%buffer)) obs%ctl%buffer(:, obs%rows) = row
            if (allocated(obs%ctl%sink)) call obs%ctl%sink%put(row)
         end if
      end associate
   contains
      !> The table's acceleration along DOF i (r_i ag, ag when the model gives no r, and r2_i ag2
      !> of a second component).
      pure real(dp) function table_along(i) result(x)
         integer, intent(in) :: i
         x = ag
         if (allocated(res%eng%r)) x = res%eng%r(i)*ag
         if (present(ag2) .and. allocated(res%eng%r2)) x = x + res%eng%r2(i)*ag2
      end function table_along
   end subroutine observe_sample

   !> Called by a technique after every accepted step. Mostly a counter; every ~10 ms of
   !> wall clock (the interval adapts to the cost of a step) it publishes the time reached,
   !> calls the progress callback when its interval has passed, and says whether the run must
   !> stop: a stop was requested, or the row sink (the history file) could not be written.
   subroutine observe_poll(obs, t, halt)
      type(observer_type), intent(inout) :: obs !! the observer
      real(dp), intent(in) :: t                !! time reached [s]
      logical, intent(out) :: halt             !! the technique must return observe_stop_error's error
      integer(int64) :: now
      real(dp) :: elapsed

      halt = .false.
      obs%countdown = obs%countdown - 1
      if (obs%countdown > 0) return
      if (.not. associated(obs%ctl)) then
         obs%countdown = huge(1)
         return
      end if
      call system_clock(now)
      elapsed = real(now - obs%last_poll, dp)/real(obs%rate, dp)
      obs%last_poll = now
      ! aim at a look every poll_target seconds
      if (elapsed < 0.5_dp*poll_target .and. obs%poll_every < 1048576) then
         obs%poll_every = 2*obs%poll_every
      else if (elapsed > 2.0_dp*poll_target .and. obs%poll_every > 1) then
         obs%poll_every = obs%poll_every/2
      end if
      obs%countdown = obs%poll_every
      obs%ctl%time = t
      if (cancel_requested(obs%ctl%cancel)) halt = .true.
      if (allocated(obs%ctl%sink)) then
         if (obs%ctl%sink%failed()) halt = .true.
      end if
      if (halt) then
         obs%stopped = .true.
         obs%stop_time = t
         return
      end if
      if (associated(obs%ctl%on_progress)) then
         if (real(now - obs%last_report, dp) >= obs%ctl%progress_interval*real(obs%rate, dp)) then
            obs%last_report = now
            call obs%ctl%on_progress(t, obs%ctl%duration)
         end if
      end if
   end subroutine observe_poll

   !> The error a technique returns when observe_poll said stop: the run was cancelled
   !> (error%stat = stat_cancelled), or the row sink (the history file) could not be written.
   subroutine observe_stop_error(obs, error)
      type(observer_type), intent(inout) :: obs          !! the observer
      type(error_type), allocatable, intent(out) :: error !! why the run stopped
      type(error_type), allocatable :: write_error

      if (associated(obs%ctl)) then
         if (allocated(obs%ctl%sink)) then
            if (obs%ctl%sink%failed()) then
               call obs%ctl%sink%finish(write_error)
               call move_alloc(write_error, error)
               return
            end if
         end if
      end if
      call fatal_error(error, "the run was cancelled at t = "//trim(fmt_real(obs%stop_time))//" s", &
                       stat=stat_cancelled)
   end subroutine observe_stop_error

   !> Count the phase changes of the devices: stick to slip (each begins a slip excursion),
   !> slip to stick, and slip reversals (slip + to slip - and back without sticking).
   pure subroutine observe_transitions(res, old, new)
      type(result_type), intent(inout) :: res  !! the result
      integer, intent(in) :: old(:)            !! phases before (0 stick, +-1 slip)
      integer, intent(in) :: new(:)            !! phases after

      integer :: d

      do d = 1, size(old)
         if (old(d) == new(d)) cycle
         if (old(d) == 0) then
            res%stick_to_slip(d) = res%stick_to_slip(d) + 1
            res%slip_excursions(d) = res%slip_excursions(d) + 1
         else if (new(d) == 0) then
            res%slip_to_stick(d) = res%slip_to_stick(d) + 1
         else
            res%reversals(d) = res%reversals(d) + 1
         end if
      end do
      if (res%n_bearings > 0) call bearing_phases(res, old, new)
   end subroutine observe_transitions

   !> Count the devices that violate the correctness condition (eqs. 9, 12) in a step
   !> accepted at time t, and keep the first times and devices. A planar bearing's condition
   !> is on its resultant, the same for its two components: it counts once, on its x component.
   pure subroutine observe_violations(res, t, ok)
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: t                !! end of the step [s]
      logical, intent(in) :: ok(:)             !! per device: the step satisfies the condition
      integer :: d

      do d = 1, size(ok)
         if (ok(d)) cycle
         if (second_component(res, d)) cycle
         res%violations = res%violations + 1
         if (res%n_violation_times < max_violation_times) then
            res%n_violation_times = res%n_violation_times + 1
            res%violation_time(res%n_violation_times) = t
            res%violation_device(res%n_violation_times) = d
         end if
      end do
   end subroutine observe_violations

   !> Whether device d is the y component of a planar bearing.
   pure logical function second_component(res, d)
      type(result_type), intent(in) :: res  !! the result
      integer, intent(in) :: d              !! the device
      integer :: b

      second_component = .false.
      do b = 1, res%n_bearings
         if (res%bearing_dev(2, b) == d) second_component = .true.
      end do
   end function second_component

   !> Close the energy balance at the end of the run: kinetic, strain and device elastic
   !> energy (end minus start), friction dissipation (device work minus stored energy) and
   !> the residual input - (kinetic + strain + viscous + friction + device elastic). The
   !> technique has handed the input and viscous work of its steps to observe_work, and the
   !> work and slip travel of each device to observe_device_motion (or into device_work and
   !> slip_travel).
   subroutine observe_end(obs, res, mass, k, u, v, e_device, w_device, tmp)
      type(observer_type), intent(inout) :: obs !! the observer
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
   !> observe_end); with devices that store energy, each one's share at the end. Each
   !> device's dissipation is its work minus the elastic energy it stores (end minus start):
   !> they sum to energy_friction_J to round-off.
   subroutine observe_end_energies(obs, res, e_kin, e_str, e_device, w_device, e_each)
      type(observer_type), intent(in) :: obs   !! the observer
      type(result_type), intent(inout) :: res  !! the result
      real(dp), intent(in) :: e_kin            !! kinetic energy at the end [J]
      real(dp), intent(in) :: e_str            !! springs' strain energy at the end [J]
      real(dp), intent(in) :: e_device         !! elastic energy stored in devices at the end [J]
      real(dp), intent(in) :: w_device         !! work of the device forces over the run [J]
      real(dp), intent(in), optional :: e_each(:) !! elastic energy of each device at the end
                                                  !! (default 0) [J]
      real(dp) :: scale
      integer :: d

      res%e_kinetic = e_kin - obs%e_kin0
      res%e_strain = e_str - obs%e_str0
      res%e_device = e_device - obs%e_dev0
      res%e_friction = w_device - res%e_device
      if (allocated(res%dissipated) .and. allocated(obs%device_work)) then
         res%slip_travel = obs%slip_travel
         do d = 1, size(res%dissipated)
            res%dissipated(d) = obs%device_work(d)
            if (present(e_each)) res%dissipated(d) = res%dissipated(d) - e_each(d)
            if (allocated(obs%e_dev0_each)) res%dissipated(d) = res%dissipated(d) + obs%e_dev0_each(d)
         end do
      end if
      res%e_residual = res%e_input - (res%e_kinetic + res%e_strain + res%e_viscous + &
                                      res%e_friction + res%e_device)
      ! the residual against the energy that passed through the structure: what it held at
      ! the start and what the table put in or took out, step by step
      scale = obs%e_kin0 + obs%e_str0 + abs(obs%e_dev0) + res%e_input_gross
      res%e_through = max(scale, 0.0_dp)
      res%e_residual_ratio = 0.0_dp
      if (scale > 0.0_dp) res%e_residual_ratio = res%e_residual/scale
      if (associated(obs%ctl)) obs%ctl%time = obs%ctl%duration   ! the run is complete
   end subroutine observe_end_energies

end module fd_observer
