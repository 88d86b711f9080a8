!> The velocity model of friction (Dimova, eqs. 6-11): a viscous coupling c1 = P mu / eps
!> inside the band |sdot| < eps (eq. 6), the Coulomb force P mu sgn(sdot) outside (eq. 7),
!> with the sign of the previous step (eq. 8). Correctness condition: eq. 9.
module fd_friction_velocity
   use fd_kinds, only: dp
   use fd_model, only: device_type
   use fd_device_state, only: device_state, phase_stick, phase_slip_pos, phase_slip_neg, &
                              job_init, job_update, job_correct
   implicit none
   private

   public :: velocity_law, velocity_init, velocity_update, velocity_correct

contains

   !> The law's entry for the dispatch (fd_friction): init, update or correct, by job.
   elemental subroutine velocity_law(job, dev, n, s, sdot, sdot_old, st, changed, ok)
      integer, intent(in) :: job                !! job_init, job_update or job_correct
      type(device_type), intent(in) :: dev      !! device parameters
      real(dp), intent(in) :: n                 !! n > 1 of the correctness condition
      real(dp), intent(in) :: s                 !! relative displacement [m]
      real(dp), intent(in) :: sdot              !! relative velocity (at the end of the step) [m/s]
      real(dp), intent(in) :: sdot_old          !! relative velocity at the start of the step [m/s]
      type(device_state), intent(inout) :: st   !! state
      logical, intent(inout) :: changed         !! update: the phase changed
      logical, intent(inout) :: ok              !! correct: the step satisfies the condition

      select case (job)
      case (job_init)
         call velocity_init(dev, s, sdot, st)
      case (job_update)
         call velocity_update(dev, s, sdot, st, changed)
      case (job_correct)
         ok = velocity_correct(dev, n, st, sdot_old, sdot)
      end select
   end subroutine velocity_law

   !> Phase at the start of a run and its force coefficients.
   pure subroutine velocity_init(dev, s, sdot, st)
      type(device_type), intent(in) :: dev   !! device parameters
      real(dp), intent(in) :: s              !! relative displacement [m]
      real(dp), intent(in) :: sdot           !! relative velocity [m/s]
      type(device_state), intent(out) :: st  !! initial state
      logical :: changed

      st%phase = phase_stick
      call velocity_update(dev, s, sdot, st, changed)
      call set_coefficients(dev, st)
   end subroutine velocity_init

   !> Phase for the next step from the velocity at the end of this one (eqs. 6-8).
   pure subroutine velocity_update(dev, s, sdot, st, changed)
      type(device_type), intent(in) :: dev      !! device parameters
      real(dp), intent(in) :: s                 !! relative displacement [m]
      real(dp), intent(in) :: sdot              !! relative velocity [m/s]
      type(device_state), intent(inout) :: st   !! state, updated
      logical, intent(out) :: changed           !! the phase changed
      integer :: old

      old = st%phase
      if (dev%p*dev%mu == 0.0_dp) then
         st%phase = phase_stick                 ! no friction capacity: F = 0, never slips
      else if (abs(sdot) < dev%eps) then
         st%phase = phase_stick
      else if (sdot > 0.0_dp) then
         st%phase = phase_slip_pos
      else
         st%phase = phase_slip_neg
      end if
      changed = st%phase /= old
      st%centre = s
      call set_coefficients(dev, st)
   end subroutine velocity_update

   !> Correctness condition, eq. 9, for a step taken in the phase st (checked in sliding).
   pure logical function velocity_correct(dev, n, st, sdot_old, sdot_new) result(ok)
      type(device_type), intent(in) :: dev   !! device parameters
      real(dp), intent(in) :: n              !! n > 1 of eq. 9
      type(device_state), intent(in) :: st   !! phase during the step
      real(dp), intent(in) :: sdot_old       !! relative velocity at t - dt [m/s]
      real(dp), intent(in) :: sdot_new       !! relative velocity at t [m/s]

      ok = .true.
      if (st%phase /= phase_stick) ok = sdot_new*sdot_old > dev%eps**2*(1.0_dp - 1.0_dp/n)
   end function velocity_correct

   pure subroutine set_coefficients(dev, st)
      type(device_type), intent(in) :: dev
      type(device_state), intent(inout) :: st

      st%ks = 0.0_dp
      if (st%phase == phase_stick) then
         st%cs = dev%p*dev%mu/dev%eps
         st%f0 = 0.0_dp
      else
         st%cs = 0.0_dp
         st%f0 = st%phase*dev%p*dev%mu
      end if
   end subroutine set_coefficients

end module fd_friction_velocity
