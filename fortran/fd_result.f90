!> Result of a run: the sampled time histories and the summary (peaks, step counts,
!> phase transitions, correctness violations, energy balance).
module fd_result
   use fd_kinds, only: dp
   implicit none
   private

   public :: result_type, max_violation_times, column_name_len

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
   end type result_type

end module fd_result
