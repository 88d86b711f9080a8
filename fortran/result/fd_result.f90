!> Result of a run: the sampled time histories and the summary (peaks, step counts,
!> phase transitions, correctness violations, energy balance).
module fd_result
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int
   use fd_model, only: model_type, integration_type
   use fd_excitation, only: excitation_type
   use fd_engineering, only: engineering_type, engineering_columns
   implicit none
   private

   public :: result_type, max_violation_times, column_name_len, init_result, history_shape

   integer, parameter :: max_violation_times = 10 !! first violation times kept
   integer, parameter :: column_name_len = 16     !! length of a column name

   !> Everything a run produces.
   type :: result_type
      integer :: n_dof = 0                              !! number of DOFs
      integer :: n_devices = 0                          !! number of friction devices
      integer :: ncol = 0                               !! columns of the history
      integer :: nout = 0                               !! samples of the history
      real(dp), allocatable :: hist(:, :)               !! history (ncol, nout)
      character(len=column_name_len), allocatable :: names(:) !! column names
      character(len=8), allocatable :: units(:)         !! column units
      ! model data
      real(dp) :: period_stuck = 0.0_dp    !! first period of the stuck system [s]
      real(dp) :: xi_stuck = 0.0_dp        !! damping ratio of that mode [-]
      real(dp) :: dt1 = 0.0_dp             !! main step [s]
      real(dp) :: dt2 = 0.0_dp             !! step around phase changes [s]
      real(dp) :: dt_min = 0.0_dp          !! floor of step halving [s]
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
      ! steps
      integer :: steps_dt1 = 0         !! steps taken with dt1
      integer :: steps_dt2 = 0         !! steps taken with dt2
      integer :: steps_finer = 0       !! steps taken with dt2/2, dt2/4, ...
      integer :: factorizations = 0    !! factorizations of the effective stiffness
                                       !! (exact technique: matrix exponentials)
      integer :: events = 0            !! events located (exact technique)
      integer :: patterns = 0          !! stick-slip patterns solved in one-step problems (Moreau-Jean)
      integer :: lcp_fallbacks = 0     !! one-step problems that needed Lemke's fallback (Moreau-Jean)
      ! correctness condition, eqs. 9 and 12
      integer :: violations = 0        !! steps accepted that violate it
      integer :: n_violation_times = 0 !! entries used in violation_time
      real(dp) :: violation_time(max_violation_times) = 0.0_dp  !! end times of the first ones [s]
      integer :: violation_device(max_violation_times) = 0      !! their devices
      ! energy [J] (relative frame)
      real(dp) :: e_input = 0.0_dp     !! work of the table's inertia loads
      real(dp) :: e_kinetic = 0.0_dp   !! kinetic energy at the end (minus initial)
      real(dp) :: e_strain = 0.0_dp    !! springs' strain energy at the end (minus initial)
      real(dp) :: e_viscous = 0.0_dp   !! viscous dissipation
      real(dp) :: e_friction = 0.0_dp  !! friction dissipation
      real(dp) :: e_device = 0.0_dp    !! elastic energy stored in sticking devices at the end
      real(dp) :: e_residual = 0.0_dp  !! input - (kinetic + strain + viscous + friction + device)
      real(dp) :: run_time = 0.0_dp    !! wall-clock time of the integration [s]
      ! names, modes, storey drifts and shears, residual values (fd_engineering)
      type(engineering_type) :: eng    !! the engineering outputs
   end type result_type

contains

   !> Size of the history a run writes: columns t, ag, (u, v, aabs) per DOF and
   !> (s, sdot, F, phase) per device, then (drift, V) per storey and Vb when the model names
   !> storeys; samples at t = 0, every `every` dt1 steps and at the end.
   pure subroutine history_shape(model, exc, opts, ncol, nout, nsteps, every)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(integration_type), intent(in) :: opts    !! integration settings
      integer, intent(out) :: ncol                  !! columns
      integer, intent(out) :: nout                  !! samples
      integer, intent(out) :: nsteps                !! dt1 steps of the run
      integer, intent(out) :: every                 !! dt1 steps between samples

      ncol = 2 + 3*model%n_dof + 4*model%n_devices + engineering_columns(model)
      nsteps = max(1, nint(exc%duration/(exc%dt_record/opts%n1)))
      every = opts%output_every
      if (every <= 0) every = opts%n1
      nout = nsteps/every + 1 + merge(1, 0, mod(nsteps, every) /= 0)
   end subroutine history_shape

   !> Allocate the history (its shape from history_shape) and the per-DOF and per-device
   !> summary of a run; return the run's number of dt1 steps and the sampling interval.
   subroutine init_result(model, exc, opts, res, nsteps, every, error)
      type(model_type), intent(in) :: model         !! the model run
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(integration_type), intent(in) :: opts    !! integration settings
      type(result_type), intent(inout) :: res       !! the result to set up
      integer, intent(out) :: nsteps                !! dt1 steps of the run
      integer, intent(out) :: every                 !! dt1 steps between samples
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      integer :: n, nd, i, c, stat

      n = model%n_dof
      nd = model%n_devices
      res%n_dof = n
      res%n_devices = nd
      call history_shape(model, exc, opts, res%ncol, res%nout, nsteps, every)
      allocate (res%hist(res%ncol, res%nout), res%names(res%ncol), res%units(res%ncol), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the history: "//trim(fmt_int(res%nout))// &
                          " samples of "//trim(fmt_int(res%ncol))//" columns (raise output_every or "// &
                          "shorten duration)")
         return
      end if
      res%hist = 0.0_dp
      res%names(1) = 't'; res%units(1) = 's'
      res%names(2) = 'ag'; res%units(2) = 'm/s2'
      c = 2
      do i = 1, n
         res%names(c + 1) = 'u'//trim(fmt_int(i)); res%units(c + 1) = 'm'
         res%names(c + 2) = 'v'//trim(fmt_int(i)); res%units(c + 2) = 'm/s'
         res%names(c + 3) = 'aabs'//trim(fmt_int(i)); res%units(c + 3) = 'm/s2'
         c = c + 3
      end do
      do i = 1, nd
         res%names(c + 1) = 's'//trim(fmt_int(i)); res%units(c + 1) = 'm'
         res%names(c + 2) = 'sdot'//trim(fmt_int(i)); res%units(c + 2) = 'm/s'
         res%names(c + 3) = 'F'//trim(fmt_int(i)); res%units(c + 3) = 'N'
         res%names(c + 4) = 'phase'//trim(fmt_int(i)); res%units(c + 4) = '-'
         c = c + 4
      end do
      if (engineering_columns(model) > 0) then
         do i = 1, model%n_storeys
            res%names(c + 1) = 'drift'//trim(fmt_int(i)); res%units(c + 1) = 'm'
            res%names(c + 2) = 'V'//trim(fmt_int(i)); res%units(c + 2) = 'N'
            c = c + 2
         end do
         res%names(c + 1) = 'Vb'; res%units(c + 1) = 'N'
      end if
      allocate (res%peak_u(n), res%peak_u_time(n), res%peak_v(n), res%peak_aabs(n), &
                res%peak_aabs_time(n))
      res%peak_u = 0.0_dp; res%peak_u_time = 0.0_dp; res%peak_v = 0.0_dp
      res%peak_aabs = 0.0_dp; res%peak_aabs_time = 0.0_dp
      allocate (res%peak_s(nd), res%peak_force(nd), res%stick_to_slip(nd), &
                res%slip_to_stick(nd), res%reversals(nd))
      res%peak_s = 0.0_dp; res%peak_force = 0.0_dp
      res%stick_to_slip = 0; res%slip_to_stick = 0; res%reversals = 0
   end subroutine init_result

end module fd_result
