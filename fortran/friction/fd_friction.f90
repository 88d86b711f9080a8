!> Dispatch over the friction laws. Adding a law means one new module (init, update,
!> correct) and one new case in each routine here.
module fd_friction
   use fd_kinds, only: dp
   use fd_model, only: device_type, law_velocity, law_hysteretic
   use fd_device_state, only: device_state
   use fd_friction_velocity, only: velocity_init, velocity_update, velocity_correct
   use fd_friction_hysteretic, only: hysteretic_init, hysteretic_update, hysteretic_correct
   implicit none
   private

   public :: friction_init, friction_update, friction_correct

contains

   !> Initial phase and force coefficients of a device.
   elemental subroutine friction_init(dev, s, sdot, st)
      type(device_type), intent(in) :: dev   !! device parameters
      real(dp), intent(in) :: s              !! relative displacement [m]
      real(dp), intent(in) :: sdot           !! relative velocity [m/s]
      type(device_state), intent(out) :: st  !! initial state

      select case (dev%law)
      case (law_velocity)
         call velocity_init(dev, s, sdot, st)
      case (law_hysteretic)
         call hysteretic_init(dev, s, sdot, st)
      end select
   end subroutine friction_init

   !> Phase of a device for the next step, from the state at the end of this one.
   elemental subroutine friction_update(dev, s, sdot, st, changed)
      type(device_type), intent(in) :: dev      !! device parameters
      real(dp), intent(in) :: s                 !! relative displacement [m]
      real(dp), intent(in) :: sdot              !! relative velocity [m/s]
      type(device_state), intent(inout) :: st   !! state, updated
      logical, intent(out) :: changed           !! the phase changed

      changed = .false.
      select case (dev%law)
      case (law_velocity)
         call velocity_update(dev, s, sdot, st, changed)
      case (law_hysteretic)
         call hysteretic_update(dev, s, sdot, st, changed)
      end select
   end subroutine friction_update

   !> Correctness condition (eqs. 9 and 12) of a step taken in phase st.
   elemental logical function friction_correct(dev, n, st, sdot_old, sdot_new) result(ok)
      type(device_type), intent(in) :: dev   !! device parameters
      real(dp), intent(in) :: n              !! n > 1 of eqs. 9 and 12
      type(device_state), intent(in) :: st   !! phase during the step
      real(dp), intent(in) :: sdot_old       !! relative velocity at t - dt [m/s]
      real(dp), intent(in) :: sdot_new       !! relative velocity at t [m/s]

      ok = .true.
      select case (dev%law)
      case (law_velocity)
         ok = velocity_correct(dev, n, st, sdot_old, sdot_new)
      case (law_hysteretic)
         ok = hysteretic_correct(dev, n, st, sdot_old, sdot_new)
      end select
   end function friction_correct

end module fd_friction
