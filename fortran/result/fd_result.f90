!> Result of a run: the sampled time histories and the summary (peaks, step counts,
!> phase transitions, correctness violations, energy balance).
module fd_result
   use fd_kinds, only: dp
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real, stat_no_memory
   use fd_model, only: model_type, integration_type
   use fd_names, only: technique_traits_type, technique_traits
   use fd_excitation, only: excitation_type
   use fd_engineering, only: engineering_type, engineering_columns
   use fd_matrices, only: modes_type
   use fd_statistics, only: newmark_stats, event_driven_stats, moreau_jean_stats, max_event_times, run_setup, &
                            technique_setup
   implicit none
   private

   public :: result_type, max_violation_times, column_name_len, init_result, history_shape, check_finite
   public :: nonfinite_history_error, history_header
   public :: max_event_times, has_envelope, run_setup, setup_of, device_bearings
   public :: resolution_none, resolution_resolved, resolution_unresolved, resolution_names
   public :: mode_resolution_limit, harmonic_error_limit, record_error_limit
   public :: residual_ratio_limit, roundoff_ratio_limit, energy_balance_of, energy_balance_names
   public :: balance_closed, balance_dissipative, balance_error, balance_digits
   public :: record_system_none, record_system_structure, record_system_stuck, record_system_free, &
             record_system_both, record_system_names

   integer, parameter :: max_violation_times = 10 !! first violation times kept
   ! the verdict of a step check (resolution/), as fd_warnings judges it from the check's figures
   integer, parameter :: resolution_none = 1        !! not applicable: no step (event-driven)
   integer, parameter :: resolution_resolved = 2    !! within its limit
   integer, parameter :: resolution_unresolved = 3  !! beyond it
   !> omega_max dt1 above which the highest modes are not resolved (pi steps a period)
   real(dp), parameter :: mode_resolution_limit = 2.0_dp
   !> a DOF's harmonic_step_error above which the step does not resolve the steady state
   real(dp), parameter :: harmonic_error_limit = 0.05_dp
   !> a DOF's record_step_error above which the step does not resolve the record
   real(dp), parameter :: record_error_limit = 0.05_dp
   !> their names in the summary
   character(len=14), parameter :: resolution_names(3) = [character(len=14) :: 'not applicable', 'resolved', &
                                                          'unresolved']
   ! the system whose record_error the record step check judges (fd_record_resolution)
   integer, parameter :: record_system_none = 1      !! not applicable
   integer, parameter :: record_system_structure = 2 !! no device: the structure
   integer, parameter :: record_system_stuck = 3     !! no device slid, every device hysteretic
   integer, parameter :: record_system_free = 4      !! a device slid
   integer, parameter :: record_system_both = 5      !! no device slid, a velocity-law one: the larger
   !> their names in the summary
   character(len=14), parameter :: record_system_names(5) = [character(len=14) :: 'not applicable', &
      'structure', 'stuck', 'free', 'stuck and free']
   integer, parameter :: column_name_len = 16     !! length of a column name
   !> |e_residual_ratio| above this: the integration dissipated (or created) a share of the
   !> energy that the motion feels (docs/theory.md section 7)
   real(dp), parameter :: residual_ratio_limit = 0.05_dp
   !> |e_residual_ratio| above this with a rule whose accounting is exact (Newmark's average
   !> acceleration, beta = 1/4 and gamma = 1/2): its residual is round-off (at most 1.8e-12
   !> on 39 769 random decks, 4.4e-13 at 1000 storeys), so a larger one means the integration
   !> lost digits (docs/theory.md section 7)
   real(dp), parameter :: roundoff_ratio_limit = 1.0e-8_dp
   integer, parameter :: balance_closed = 1       !! |ratio| <= residual_ratio_limit (roundoff_ratio_limit)
   integer, parameter :: balance_dissipative = 2  !! the method's numerical damping beyond it
   integer, parameter :: balance_error = 3        !! an energy error of the step beyond it
   integer, parameter :: balance_digits = 4       !! round-off beyond roundoff_ratio_limit (exact accounting)
   !> their names in the summary
   character(len=12), parameter :: energy_balance_names(4) = [character(len=12) :: 'closed', 'dissipative', &
                                                              'energy error', 'digits lost']

   !> Everything a run produces.
   type :: result_type
      integer :: n_dof = 0                              !! number of DOFs
      integer :: n_devices = 0                          !! number of friction devices
      integer :: ncol = 0                               !! columns of the history
      integer :: nout = 0                               !! samples of the history
      real(dp), allocatable :: hist(:, :)               !! history (ncol, nout)
      character(len=column_name_len), allocatable :: names(:) !! column names
      character(len=8), allocatable :: units(:)         !! column units
      ! the step checks (resolution/): whether each applies to the run (its figures are set);
      ! their verdicts are the check records' (fd_warnings' run_checks), from those figures
      real(dp) :: omega_max = 0.0_dp       !! highest natural circular frequency integrated at dt1 [rad/s]
      logical :: mode_checked = .false.    !! omega_max is set: the highest modes against dt1
      logical :: harmonic_checked = .false. !! harmonic_error is set: a harmonic table motion
      logical :: record_checked = .false.  !! record_error is set: a recorded table motion
      integer :: record_system = 1         !! the system record_error judges (record_system_*)
      logical :: stick_checked = .false.   !! stick_ringing_ratio is set: sticking springs watched
      logical :: band_checked = .false.    !! band_alternation is set: velocity-law bands watched
      integer :: technique = 0             !! technique id of the run (fd_names)
      ! peaks per DOF (over every step taken)
      real(dp), allocatable :: peak_u(:)        !! max |u| [m]
      real(dp), allocatable :: peak_u_time(:)   !! time of max |u| [s]
      real(dp), allocatable :: peak_v(:)        !! max |v| [m/s]
      real(dp), allocatable :: peak_aabs(:)     !! max |absolute acceleration| [m/s2]
      real(dp), allocatable :: peak_aabs_time(:) !! time of max |aabs| [s]
      ! per device
      real(dp), allocatable :: peak_s(:)        !! max |relative displacement| [m]
      real(dp), allocatable :: peak_force(:)    !! max |friction force| [N]
      integer, allocatable :: stick_to_slip(:)  !! stick-to-slip transitions
      integer, allocatable :: slip_to_stick(:)  !! slip-to-stick transitions
      integer, allocatable :: reversals(:)      !! slip+ to slip- and back, without sticking
      integer, allocatable :: slip_excursions(:) !! slides: stick-to-slip transitions, and one for a
                                                 !! device sliding at t = 0
      real(dp), allocatable :: dissipated(:)    !! its friction dissipation: the work of its force
                                                !! over its relative motion minus the elastic energy
                                                !! it stores (end minus start) [J]
      real(dp), allocatable :: slip_travel(:)   !! integral of |ds| while it slides [m]
      ! per planar bearing (&bearings: two devices, its x and y components)
      integer :: n_bearings = 0                 !! bearings
      integer, allocatable :: bearing_dev(:, :) !! (2, n_bearings) the devices of its x and y components
      real(dp), allocatable :: bearing_peak(:)  !! max |(s_x, s_y)|, the resultant displacement [m]
      real(dp), allocatable :: bearing_peak_angle(:) !! its direction, from x counter-clockwise [deg]
      real(dp), allocatable :: bearing_peak_time(:)  !! its time [s]
      real(dp), allocatable :: bearing_last(:, :)    !! (2, n_bearings) (s_x, s_y) at the last step observed [m]
      ! each bearing's travel and reversals, and the isolation system's shear (fd_observer's
      ! observe_bearings; the sliding flags follow observe_transitions)
      real(dp), allocatable :: bearing_k(:)          !! its pendulum's restoring stiffness p / R (0: flat) [N/m]
      real(dp), allocatable :: bearing_travel(:)     !! path length of (s_x, s_y) over the steps it slid in [m]
      integer, allocatable :: bearing_reversals(:)   !! turns of its sliding direction by 180 deg without sticking
      logical, allocatable :: bearing_sliding(:)     !! it slides (its components' phase is not stick)
      logical, allocatable :: bearing_slid(:)        !! it slid in the step being taken (at its start or since)
      real(dp), allocatable :: bearing_dir(:, :)     !! (2, n_bearings) its friction force at the last sliding
                                                     !! step observed; 0 at a slide's start [N]
      real(dp), allocatable :: bearing_turn(:)       !! signed turn of that force since the slide's start,
                                                     !! less 180 deg a reversal counted [rad]
      logical :: bearing_seen = .false.              !! a state was observed (the first sets bearing_last)
      real(dp) :: peak_iso_shear(3) = 0.0_dp         !! max |Vx|, |Vy|, |(Vx, Vy)| of the bearings together [N]
      real(dp) :: peak_iso_shear_time(3) = 0.0_dp    !! their times [s]
      ! its normal force N (constant P, or varying with a vertical component) and its uplift (N <= 0)
      real(dp), allocatable :: bearing_n_min(:)      !! min N over the accepted states [N]
      real(dp), allocatable :: bearing_n_max(:)      !! max N [N]
      real(dp), allocatable :: bearing_n_last(:)     !! N at the last state observed [N]
      integer, allocatable :: bearing_uplifts(:)     !! uplift episodes (N falls to <= 0)
      real(dp), allocatable :: bearing_uplift_time(:)  !! time spent lifted: the steps that start at N <= 0 [s]
      real(dp), allocatable :: bearing_uplift_first(:) !! start of the first episode [s]
      real(dp), allocatable :: bearing_uplift_peak(:)  !! peak uplift displacement (allocated when a bearing
                                                       !! has an elastic vertical support, kv > 0) [m]
      real(dp), allocatable :: harmonic_error(:)      !! per DOF: the step's error in the linear steady state
      real(dp), allocatable :: record_error(:)        !! per DOF: the step's error in the linear peak response
                                                      !! of the system the run was in
      real(dp), allocatable :: record_error_stuck(:)  !! the same, of the stuck system
      real(dp), allocatable :: record_error_free(:)   !! the same, of the free system
      real(dp), allocatable :: stick_freq_error(:)    !! 1 - omega~/omega of the sticking spring's mode
      real(dp), allocatable :: stick_ringing_ratio(:) !! largest ringing / margin of a dephased stick phase
      real(dp), allocatable :: stick_ringing(:)       !! that phase's ringing amplitude [N]
      real(dp), allocatable :: stick_margin(:)        !! that phase's margin P mu - max |F| [N]
      real(dp), allocatable :: band_x(:)              !! velocity law: (1 - gamma) dt1 (c_i / m_i + c_j / m_j)
      real(dp), allocatable :: band_alternation(:)    !! largest step-to-step alternation of the
                                                      !! band's force counted [N]
      real(dp), allocatable :: band_alternation_time(:) !! time of the steps counted [s]
      ! what the technique did: each technique counts in its own type (fd_statistics), the
      ! others stay 0
      type(newmark_stats) :: newmark            !! Newmark's steps, refinements, factorizations
      type(event_driven_stats) :: exact         !! the exact technique's intervals, events
      type(moreau_jean_stats) :: moreau_jean    !! Moreau-Jean's steps, patterns, fallbacks
      integer :: env_col = 0           !! first column of the maxima between rows (0: none)
      ! correctness condition, eqs. 9 and 12
      integer :: violations = 0        !! steps accepted that violate it
      integer :: n_violation_times = 0 !! entries used in violation_time
      real(dp) :: violation_time(max_violation_times) = 0.0_dp  !! end times of the first ones [s]
      integer :: violation_device(max_violation_times) = 0      !! their devices
      ! a speed-dependent mu, taken at the velocity at each step's end (Newmark)
      integer :: mu_unconverged = 0    !! steps accepted with those forces unconverged
      real(dp) :: mu_unconverged_time = 0.0_dp !! end of the first one [s]
      real(dp) :: mu_misfit = 0.0_dp   !! the largest change their last pass asked for, |df| / (P mu_largest) [-]
      ! energy [J] (relative frame)
      real(dp) :: e_input = 0.0_dp     !! work of the table's inertia loads
      real(dp) :: e_kinetic = 0.0_dp   !! kinetic energy at the end (minus initial)
      real(dp) :: e_strain = 0.0_dp    !! springs' strain energy at the end (minus initial)
      real(dp) :: e_viscous = 0.0_dp   !! viscous dissipation
      real(dp) :: e_friction = 0.0_dp  !! friction dissipation
      real(dp) :: e_device = 0.0_dp    !! elastic energy stored in sticking devices at the end
      real(dp) :: e_residual = 0.0_dp  !! input - (kinetic + strain + viscous + friction + device)
      real(dp) :: e_input_gross = 0.0_dp !! sum over the steps of |input work of the step|
      real(dp) :: e_residual_ratio = 0.0_dp !! e_residual / e_through (0 when e_through is 0)
      real(dp) :: e_through = 0.0_dp   !! initial energy + e_input_gross (0: the ratio is undefined)
      real(dp) :: run_time = 0.0_dp    !! wall-clock time of the integration [s]
      real(dp) :: record_pga = 0.0_dp  !! a record's max |table acceleration| fed to the run [m/s2]
                                       !! (0: no record)
      ! names, modes, storey drifts and shears, residual values (fd_engineering)
      type(engineering_type) :: eng    !! the engineering outputs
   end type result_type

contains

   !> What the set-up of the technique that ran fixed (fd_statistics' run_setup): its steps
   !> dt1, dt2, dt_min, the stuck system's first mode, its rule's energy accounting.
   pure function setup_of(res) result(s)
      type(result_type), intent(in) :: res   !! the result
      type(run_setup) :: s                   !! the set-up of its technique

      s = technique_setup(res%newmark, res%exact, res%moreau_jean)
   end function setup_of

   !> The summary's energy_balance (its check's verdict, fd_warnings). With a rule
   !> whose accounting is exact (exact_accounting: Newmark's average acceleration) the residual
   !> is round-off: balance_closed when |e_residual_ratio| <= roundoff_ratio_limit, else
   !> balance_digits (the integration lost digits: a coupling far stiffer than the step, such
   !> as a velocity-law band whose P mu / eps is huge for its masses). Otherwise
   !> balance_closed when |e_residual_ratio| <= residual_ratio_limit; beyond, balance_dissipative
   !> when the ratio is positive and the method damps (damping_method: Newmark gamma > 1/2,
   !> Moreau-Jean theta > 1/2), else balance_error (Newmark beta /= 1/4, a step beyond its
   !> rule's stability limit). Named by
   !> energy_balance_names (a fixed-length table, as resolution_names: a deferred-length
   !> function result came back empty in one of many concurrent runs of the checked build).
   pure integer function energy_balance_of(ratio, damping_method, exact_accounting) result(energy_balance)
      real(dp), intent(in) :: ratio          !! e_residual_ratio
      logical, intent(in) :: damping_method  !! the method has numerical damping
      logical, intent(in) :: exact_accounting !! the residual of the method is round-off

      if (exact_accounting) then
         energy_balance = merge(balance_closed, balance_digits, abs(ratio) <= roundoff_ratio_limit)
      else if (abs(ratio) <= residual_ratio_limit) then
         energy_balance = balance_closed
      else if (ratio > 0.0_dp .and. damping_method) then
         energy_balance = balance_dissipative
      else
         energy_balance = balance_error
      end if
   end function energy_balance_of

   !> Whether a run of these settings writes, after the state columns, the maxima of |u|,
   !> |v|, |aabs| per DOF, |s|, |F| per device and |drift|, |V| per storey and |Vb| since the
   !> previous row (a technique whose solution between rows is known: its traits' envelope).
   pure logical function has_envelope(opts)
      type(integration_type), intent(in) :: opts    !! integration settings
      type(technique_traits_type) :: traits

      traits = technique_traits(opts%technique)
      has_envelope = traits%envelope
   end function has_envelope

   !> Size of the history a run writes: columns t, ag, (u, v, aabs) per DOF and
   !> (s, sdot, F, phase) per device, then (drift, V) per storey and Vb when the model names
   !> storeys, then N per planar bearing when it has bearings, then (exact technique) the
   !> maxima since the previous row: (peak_u, peak_v, peak_aabs) per DOF, (peak_s, peak_F) per
   !> device and (peak_drift, peak_V) per storey and peak_Vb; of the DOFs and devices only those
   !> kept when given (the storey and bearing columns always); samples at t = 0, every `every`
   !> dt1 steps and at the end.
   pure subroutine history_shape(model, exc, opts, ncol, nout, nsteps, every, n_dof_kept, n_devices_kept)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(integration_type), intent(in) :: opts    !! integration settings
      integer, intent(out) :: ncol                  !! columns
      integer, intent(out) :: nout                  !! samples
      integer, intent(out) :: nsteps                !! dt1 steps of the run
      integer, intent(out) :: every                 !! dt1 steps between samples
      integer, intent(in), optional :: n_dof_kept   !! DOFs in the history (default all)
      integer, intent(in), optional :: n_devices_kept !! devices in the history (default all)
      integer :: nk, ndk

      nk = model%n_dof
      ndk = model%n_devices
      if (present(n_dof_kept)) nk = n_dof_kept
      if (present(n_devices_kept)) ndk = n_devices_kept
      ncol = 2 + 3*nk + 4*ndk + engineering_columns(model) + bearings_of(model)
      if (has_envelope(opts)) ncol = ncol + 3*nk + 2*ndk + engineering_columns(model)
      nsteps = max(1, nint(exc%duration/(exc%dt_record/opts%n1)))
      every = opts%output_every
      if (every <= 0) every = opts%n1
      nout = nsteps/every + 1 + merge(1, 0, mod(nsteps, every) /= 0)
   end subroutine history_shape

   !> Allocate the history (its shape from history_shape; no rows when `keep` is false:
   !> they go elsewhere) and the per-DOF and per-device summary of a run; return the run's
   !> number of dt1 steps and the sampling interval. `dofs` and `devices` name the DOFs and
   !> devices whose columns the history has (default: all).
   subroutine init_result(model, exc, opts, res, nsteps, every, error, dofs, devices, keep)
      type(model_type), intent(in) :: model         !! the model run
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(integration_type), intent(in) :: opts    !! integration settings
      type(result_type), intent(inout) :: res       !! the result to set up
      integer, intent(out) :: nsteps                !! dt1 steps of the run
      integer, intent(out) :: every                 !! dt1 steps between samples
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      integer, intent(in), optional :: dofs(:)      !! DOFs in the history (ascending)
      integer, intent(in), optional :: devices(:)   !! devices in the history (ascending)
      logical, intent(in), optional :: keep         !! hold the rows here (default true)
      ! the history's columns of a DOF (and its peaks', envelope)
      character(len=4), parameter :: dof_names(3) = [character(len=4) :: 'u', 'v', 'aabs']
      character(len=4), parameter :: dof_units(3) = [character(len=4) :: 'm', 'm/s', 'm/s2']
      integer, allocatable :: kd(:), kv(:)
      integer :: n, nd, i, c, stat, rows

      n = model%n_dof
      nd = model%n_devices
      res%n_dof = n
      res%n_devices = nd
      if (present(dofs)) then
         allocate (kd, source=dofs)
      else
         allocate (kd, source=[(i, i=1, n)])
      end if
      if (present(devices)) then
         allocate (kv, source=devices)
      else
         allocate (kv, source=[(i, i=1, nd)])
      end if
      call history_shape(model, exc, opts, res%ncol, res%nout, nsteps, every, size(kd), size(kv))
      rows = res%nout
      if (present(keep)) then
         if (.not. keep) rows = 0
      end if
      allocate (res%hist(res%ncol, rows), res%names(res%ncol), res%units(res%ncol), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the history: "//trim(fmt_int(res%nout))// &
                          " samples of "//trim(fmt_int(res%ncol))//" columns (raise output_every, "// &
                          "keep fewer DOFs and devices, or stream the history to its file)", stat_no_memory)
         return
      end if
      res%hist = 0.0_dp
      res%names(1) = 't'; res%units(1) = 's'
      res%names(2) = 'ag'; res%units(2) = 'm/s2'
      c = 2
      call add_columns(res, c, '', kd, dof_names, dof_units)
      call add_columns(res, c, '', kv, [character(len=5) :: 's', 'sdot', 'F', 'phase'], [character(len=3) :: 'm', 'm/s', 'N', '-'])
      if (engineering_columns(model) > 0) call storey_columns(res, c, '', model%n_storeys)
      ! each planar bearing's normal force (always all of them)
      call add_columns(res, c, '', [(i, i=1, bearings_of(model))], [character(len=1) :: 'N'], [character(len=1) :: 'N'])
      if (has_envelope(opts)) then
         res%env_col = c + 1
         call add_columns(res, c, 'peak_', kd, dof_names, dof_units)
         call add_columns(res, c, 'peak_', kv, [character(len=1) :: 's', 'F'], [character(len=1) :: 'm', 'N'])
         if (engineering_columns(model) > 0) call storey_columns(res, c, 'peak_', model%n_storeys)
      end if
      allocate (res%peak_u(n), res%peak_u_time(n), res%peak_v(n), res%peak_aabs(n), &
                res%peak_aabs_time(n), res%peak_s(nd), res%peak_force(nd), res%stick_to_slip(nd), &
                res%slip_to_stick(nd), res%reversals(nd), res%slip_excursions(nd), res%dissipated(nd), &
                res%slip_travel(nd), res%harmonic_error(n), res%record_error(n), &
                res%record_error_stuck(n), res%record_error_free(n), &
                res%stick_freq_error(nd), res%stick_ringing_ratio(nd), res%stick_ringing(nd), &
                res%stick_margin(nd), res%band_x(nd), res%band_alternation(nd), &
                res%band_alternation_time(nd), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the summary of "//trim(fmt_int(n))//" DOFs and "// &
                          trim(fmt_int(nd))//" devices", stat_no_memory)
         return
      end if
      res%peak_u = 0.0_dp; res%peak_u_time = 0.0_dp; res%peak_v = 0.0_dp
      res%peak_aabs = 0.0_dp; res%peak_aabs_time = 0.0_dp
      res%peak_s = 0.0_dp; res%peak_force = 0.0_dp
      res%stick_to_slip = 0; res%slip_to_stick = 0; res%reversals = 0; res%slip_excursions = 0
      res%dissipated = 0.0_dp; res%slip_travel = 0.0_dp
      res%harmonic_error = 0.0_dp; res%record_error = 0.0_dp
      res%record_error_stuck = 0.0_dp; res%record_error_free = 0.0_dp
      res%stick_freq_error = 0.0_dp; res%stick_ringing_ratio = 0.0_dp
      res%stick_ringing = 0.0_dp; res%stick_margin = 0.0_dp
      res%band_x = 0.0_dp; res%band_alternation = 0.0_dp; res%band_alternation_time = 0.0_dp
      call init_bearings(model, res, error)
   end subroutine init_result

   !> The planar bearings of a model: its devices that are a bearing's x component.
   pure integer function bearings_of(model) result(nb)
      type(model_type), intent(in) :: model         !! the model
      integer :: d

      nb = 0
      do d = 1, model%n_devices
         if (model%dev(d)%component == 1) nb = nb + 1
      end do
   end function bearings_of

   !> The planar bearings' part of the result: each bearing's two devices (x, y), its peaks at 0.
   subroutine init_bearings(model, res, error)
      type(model_type), intent(in) :: model         !! the model run
      type(result_type), intent(inout) :: res       !! the result
      type(error_type), allocatable, intent(out) :: error !! no memory
      integer :: d, b, nb, stat

      nb = 0
      do d = 1, model%n_devices
         if (model%dev(d)%component == 1) nb = nb + 1
      end do
      res%n_bearings = nb
      allocate (res%bearing_dev(2, nb), res%bearing_peak(nb), res%bearing_peak_angle(nb), res%bearing_peak_time(nb), &
                res%bearing_last(2, nb), res%bearing_n_min(nb), res%bearing_n_max(nb), res%bearing_n_last(nb), &
                res%bearing_uplifts(nb), res%bearing_uplift_time(nb), res%bearing_uplift_first(nb), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the summary of "//trim(fmt_int(nb))//" bearings", stat_no_memory)
         return
      end if
      b = 0
      do d = 1, model%n_devices
         if (model%dev(d)%component /= 1) cycle
         b = b + 1
         res%bearing_dev(:, b) = [d, model%dev(d)%partner]
         res%bearing_n_min(b) = model%dev(d)%p
         res%bearing_n_max(b) = model%dev(d)%p
         res%bearing_n_last(b) = model%dev(d)%p
      end do
      res%bearing_uplifts = 0; res%bearing_uplift_time = 0.0_dp; res%bearing_uplift_first = 0.0_dp
      if (any(model%dev(1:model%n_devices)%kv > 0.0_dp)) then
         allocate (res%bearing_uplift_peak(nb), stat=stat)
         if (stat /= 0) then
            call fatal_error(error, "not enough memory for the summary of "//trim(fmt_int(nb))//" bearings", &
                             stat_no_memory)
            return
         end if
         res%bearing_uplift_peak = 0.0_dp
      end if
      res%bearing_peak = 0.0_dp; res%bearing_peak_angle = 0.0_dp; res%bearing_peak_time = 0.0_dp
      res%bearing_last = 0.0_dp
      call init_isolation(model, res, error)
   end subroutine init_bearings

   !> Each device's planar bearing (0: a device of its own), from res%bearing_dev.
   pure subroutine device_bearings(res, bof)
      type(result_type), intent(in) :: res          !! the result, its bearings set up
      integer, intent(out) :: bof(:)                !! (n_devices) each device's bearing
      integer :: b

      bof = 0
      do b = 1, res%n_bearings
         bof(res%bearing_dev(1, b)) = b
         bof(res%bearing_dev(2, b)) = b
      end do
   end subroutine device_bearings

   !> Each bearing's travel, reversals and restoring stiffness, and the isolation shear's
   !> peaks, at 0.
   subroutine init_isolation(model, res, error)
      type(model_type), intent(in) :: model         !! the model run
      type(result_type), intent(inout) :: res       !! the result, its bearings set up
      type(error_type), allocatable, intent(out) :: error !! no memory
      integer :: b, d, nb, stat

      nb = res%n_bearings
      allocate (res%bearing_k(nb), res%bearing_travel(nb), res%bearing_reversals(nb), res%bearing_sliding(nb), &
                res%bearing_slid(nb), res%bearing_dir(2, nb), res%bearing_turn(nb), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the summary of "//trim(fmt_int(nb))//" bearings", stat_no_memory)
         return
      end if
      do b = 1, nb
         d = res%bearing_dev(1, b)
         res%bearing_k(b) = 0.0_dp
         if (model%dev(d)%radius > 0.0_dp) res%bearing_k(b) = model%dev(d)%p/model%dev(d)%radius
      end do
      res%bearing_travel = 0.0_dp; res%bearing_reversals = 0; res%bearing_sliding = .false.
      res%bearing_slid = .false.
      res%bearing_dir = 0.0_dp; res%bearing_turn = 0.0_dp; res%bearing_seen = .false.
      res%peak_iso_shear = 0.0_dp; res%peak_iso_shear_time = 0.0_dp
   end subroutine init_isolation

   !> For each id, the history's columns prefix//name//id [unit], one for each name, from
   !> column c + 1; c becomes the last column named.
   pure subroutine add_columns(res, c, prefix, ids, names, units)
      type(result_type), intent(inout) :: res       !! its names and units
      integer, intent(inout) :: c                   !! the last column named
      character(len=*), intent(in) :: prefix        !! before each name ('peak_' for the envelope)
      integer, intent(in) :: ids(:)                 !! DOFs, devices or storeys
      character(len=*), intent(in) :: names(:)      !! the quantities of each
      character(len=*), intent(in) :: units(:)      !! their units
      integer :: j, k

      do j = 1, size(ids)
         do k = 1, size(names)
            res%names(c + k) = prefix//trim(names(k))//trim(fmt_int(ids(j))); res%units(c + k) = units(k)
         end do
         c = c + size(names)
      end do
   end subroutine add_columns

   !> The history's columns of each storey's drift and shear, then of the base shear.
   pure subroutine storey_columns(res, c, prefix, n_storeys)
      type(result_type), intent(inout) :: res       !! its names and units
      integer, intent(inout) :: c                   !! the last column named
      character(len=*), intent(in) :: prefix        !! before each name ('peak_' for the envelope)
      integer, intent(in) :: n_storeys              !! storeys of the model
      integer :: j

      call add_columns(res, c, prefix, [(j, j=1, n_storeys)], [character(len=5) :: 'drift', 'V'], &
                       [character(len=1) :: 'm', 'N'])
      res%names(c + 1) = prefix//'Vb'; res%units(c + 1) = 'N'
      c = c + 1
   end subroutine storey_columns

   !> The header line of the history: name[unit] of each column, comma separated.
   pure subroutine history_header(res, line)
      type(result_type), intent(in) :: res                 !! the result
      character(len=:), allocatable, intent(out) :: line   !! the header
      integer :: j, pos, n

      n = 0
      do j = 1, res%ncol
         n = n + len_trim(res%names(j)) + len_trim(res%units(j)) + 3
      end do
      allocate (character(len=max(n - 1, 0)) :: line)
      pos = 0
      do j = 1, res%ncol
         n = len_trim(res%names(j)) + len_trim(res%units(j)) + 2
         line(pos + 1:pos + n) = trim(res%names(j))//'['//trim(res%units(j))//']'
         pos = pos + n
         if (j < res%ncol) then
            line(pos + 1:pos + 1) = ','
            pos = pos + 1
         end if
      end do
   end subroutine history_header

   !> Every number of a result must be finite: an error names the first quantity that is not
   !> (its summary key, or its history column and time), never a null in a summary.
   subroutine check_finite(res, error)
      type(result_type), intent(in) :: res                !! the result of a run
      type(error_type), allocatable, intent(out) :: error !! the first quantity not finite
      type(run_setup) :: setup
      integer :: i, j

      setup = setup_of(res)
      call scalar('period_stuck_s', setup%period_stuck)
      call scalar('xi_stuck', setup%xi_stuck)
      call scalar('energy_input_J', res%e_input)
      call scalar('energy_kinetic_J', res%e_kinetic)
      call scalar('energy_strain_J', res%e_strain)
      call scalar('energy_viscous_J', res%e_viscous)
      call scalar('energy_friction_J', res%e_friction)
      call scalar('energy_device_elastic_J', res%e_device)
      call scalar('energy_residual_J', res%e_residual)
      if (allocated(error)) return
      if (allocated(res%peak_u)) call vector('peak_u_m', res%peak_u)
      if (allocated(res%peak_v)) call vector('peak_v_mps', res%peak_v)
      if (allocated(res%peak_aabs)) call vector('peak_aabs_mps2', res%peak_aabs)
      if (allocated(res%peak_s)) call vector('peak_s_m', res%peak_s)
      if (allocated(res%peak_force)) call vector('peak_force_N', res%peak_force)
      if (allocated(res%dissipated)) call vector('dissipated_energy_J', res%dissipated)
      if (allocated(res%slip_travel)) call vector('slip_travel_m', res%slip_travel)
      if (allocated(res%bearing_travel)) call vector('bearing_slip_travel_m', res%bearing_travel)
      if (res%n_bearings > 0) then
         call scalar('peak_isolation_shear_x_N', res%peak_iso_shear(1))
         call scalar('peak_isolation_shear_y_N', res%peak_iso_shear(2))
         call scalar('peak_isolation_shear_N', res%peak_iso_shear(3))
      end if
      call engineering()
      if (allocated(error) .or. .not. allocated(res%hist)) return
      do j = 1, min(res%nout, size(res%hist, 2))
         do i = 1, size(res%hist, 1)
            if (ieee_is_finite(res%hist(i, j))) cycle
            call nonfinite_history_error(res%names(i), res%hist(1, j), res%hist(i, j), error)
            return
         end do
      end do
   contains
      !> The engineering outputs (fd_engineering): damping, modes (a rigid-body mode's
      !> infinite period and undefined damping ratio are written as 0), storeys, residuals.
      subroutine engineering()
         if (allocated(error)) return
         call scalar('damping_a0_per_s', res%eng%a0)
         call scalar('damping_a1_s', res%eng%a1)
         call modes('stuck', res%eng%stuck)
         call modes('free', res%eng%free)
         if (allocated(res%eng%residual_s)) call vector('residual_s_m', res%eng%residual_s)
         if (allocated(res%eng%peak_drift)) call vector('peak_drift_m', res%eng%peak_drift)
         if (allocated(res%eng%drift)) call vector('residual_drift_m', res%eng%drift)
         if (allocated(res%eng%peak_shear)) then
            call scalar('peak_base_shear_N', res%eng%peak_shear(0))
            call vector('peak_storey_shear_N', res%eng%peak_shear(1:))
         end if
         if (allocated(res%eng%shear)) then
            call scalar('residual_base_shear_N', res%eng%shear(0))
            call vector('residual_storey_shear_N', res%eng%shear(1:))
         end if
      end subroutine engineering
      subroutine modes(name, m)
         character(len=*), intent(in) :: name
         type(modes_type), intent(in) :: m
         integer :: k
         if (m%n == 0 .or. allocated(error)) return
         do k = 1, m%n
            if (m%omega2(k) == 0.0_dp) cycle
            call scalar('periods_'//name//'_s('//trim(fmt_int(k))//')', m%period(k))
            call scalar('modal_xi_'//name//'('//trim(fmt_int(k))//')', m%xi(k))
         end do
         call vector('modal_mass_ratio_'//name, m%mass_ratio)
         do k = 1, m%n
            call vector('mode_shapes_'//name//'('//trim(fmt_int(k))//')', m%shape(:, k))
         end do
      end subroutine modes
      subroutine scalar(key, x)
         character(len=*), intent(in) :: key
         real(dp), intent(in) :: x
         if (allocated(error)) return
         if (ieee_is_finite(x)) return
         call fatal_error(error, "the run produced a value that is not finite (overflow): "//key//" = "// &
                          trim(fmt_real(x))//"; the deck's values are too large (or too small) for double precision")
      end subroutine scalar
      subroutine vector(key, x)
         character(len=*), intent(in) :: key
         real(dp), intent(in) :: x(:)
         integer :: k
         if (allocated(error)) return
         do k = 1, size(x)
            if (ieee_is_finite(x(k))) cycle
            call scalar(key//'('//trim(fmt_int(k))//')', x(k))
            return
         end do
      end subroutine vector
   end subroutine check_finite

   !> The error of a history value that is not finite: column `name` at time t.
   subroutine nonfinite_history_error(name, t, x, error)
      character(len=*), intent(in) :: name               !! the column
      real(dp), intent(in) :: t                           !! the row's time [s]
      real(dp), intent(in) :: x                           !! the value
      type(error_type), allocatable, intent(out) :: error !! the error

      call fatal_error(error, "the run produced a value that is not finite (overflow): history column "// &
                       trim(name)//" at t = "//trim(fmt_real(t))//" s is "//trim(fmt_real(x))// &
                       "; the deck's values are too large (or too small) for double precision")
   end subroutine nonfinite_history_error

end module fd_result
