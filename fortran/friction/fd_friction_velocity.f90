!> The velocity model of friction (Dimova, eqs. 6-11): a viscous coupling c1 = P mu / eps
!> inside the band |sdot| < eps (eq. 6), the Coulomb force P mu sgn(sdot) outside (eq. 7),
!> with the sign of the previous step (eq. 8). Correctness condition: eq. 9.
!>
!> Velocity-dependent friction (the paper's natural extension of this law): mu may be a
!> function of the sliding speed |sdot|, mu_max - (mu_max - mu_min) exp(-rate |sdot|) or
!> linear between the points of a table. The sign is the previous step's (eq. 8); mu is the
!> one at the velocity at the step's end, as a Newton code's trial takes it: the time-step
!> loop iterates the sliding force P mu(|sdot|) sgn to a fixed point of the step
!> (velocity_follow gives it; the force stays a load, so nothing is refactored). Inside the
!> band the coupling is P mu(eps) / eps, continuous with the sliding force at |sdot| = eps.
module fd_friction_velocity
   use fd_kinds, only: dp
   use fd_model, only: device_type, mu_constant, mu_exponential, mu_table, sliding_mu
   use fd_device_state, only: device_state, phase_stick, phase_slip_pos, phase_slip_neg, &
                              law_traits_type, stuck_dashpot
   implicit none
   private

   public :: velocity_init, velocity_update, velocity_correct, velocity_settle, velocity_follow
   public :: velocity_traits, velocity_damping, velocity_holds, velocity_capacity, largest_mu

contains

   !> What the velocity law says of itself: while it sticks, a dashpot (its band's coupling
   !> P mu(eps) / eps, set by eps) in the band |sdot| < eps; Newmark checks eq. 9 in its slides;
   !> its band's force may alternate from step to step; it stores no energy; mu may depend on
   !> the sliding speed.
   pure function velocity_traits() result(traits)
      type(law_traits_type) :: traits   !! the velocity law's traits

      traits = law_traits_type(stuck=stuck_dashpot, band_name='eps', coupling_name='eps', checks_correctness=.true., &
                               checks_band_alternation=.true., mu_of_speed=.true.)
   end function velocity_traits

   !> The band's coupling P mu(eps) / eps [N s/m]: the dashpot of a sticking device (eq. 6).
   elemental real(dp) function velocity_damping(dev) result(c)
      type(device_type), intent(in) :: dev   !! device parameters

      c = dev%p*sliding_mu(dev, dev%eps)/dev%eps
   end function velocity_damping

   !> Whether a sticking device holds its nodes together: through its band's coupling, so
   !> P mu(eps) > 0 (a speed-dependent mu that is 0 in the band holds nothing).
   elemental logical function velocity_holds(dev) result(holds)
      type(device_type), intent(in) :: dev   !! device parameters

      holds = dev%p*sliding_mu(dev, dev%eps) > 0.0_dp
   end function velocity_holds

   !> The friction capacity P mu_max [N], mu_max the largest mu at any sliding speed.
   elemental real(dp) function velocity_capacity(dev) result(cap)
      type(device_type), intent(in) :: dev   !! device parameters

      cap = dev%p*largest_mu(dev)
   end function velocity_capacity

   !> The largest friction coefficient of a device at any sliding speed: mu itself (constant
   !> law; exponential, where it is mu_max; the larger of it and mu_min), or the table's largest
   !> value. P times it is the device's friction capacity: a device with none never slips.
   elemental real(dp) function largest_mu(dev) result(mu)
      type(device_type), intent(in) :: dev   !! device parameters

      mu = dev%mu
      if (dev%mu_law == mu_table) mu = maxval(dev%mu_at(1:dev%n_mu_points))
      if (dev%mu_law == mu_exponential) mu = max(dev%mu, dev%mu_min)
   end function largest_mu

   !> Phase at the start of a run and its force coefficients.
   pure subroutine velocity_init(dev, s, sdot, st)
      type(device_type), intent(in) :: dev   !! device parameters
      real(dp), intent(in) :: s              !! relative displacement [m]
      real(dp), intent(in) :: sdot           !! relative velocity [m/s]
      type(device_state), intent(out) :: st  !! initial state
      logical :: changed

      st%phase = phase_stick
      call velocity_update(dev, s, sdot, st, changed)
      call set_coefficients(dev, sdot, st)
   end subroutine velocity_init

   !> Phase for the next step from the velocity at the end of this one (eqs. 6-8).
   !> st comes from velocity_init or an earlier update: its coefficients are those of its
   !> phase.
   pure subroutine velocity_update(dev, s, sdot, st, changed)
      type(device_type), intent(in) :: dev      !! device parameters
      real(dp), intent(in) :: s                 !! relative displacement [m]
      real(dp), intent(in) :: sdot              !! relative velocity [m/s]
      type(device_state), intent(inout) :: st   !! state, updated
      logical, intent(out) :: changed           !! the phase changed
      integer :: old

      old = st%phase
      if (abs(sdot) < dev%eps) then
         st%phase = phase_stick
      else if (sdot > 0.0_dp) then
         st%phase = phase_slip_pos
      else
         st%phase = phase_slip_neg
      end if
      ! no friction capacity: F = 0, never slips (mu <= largest_mu, mu >= 0: the cheap test first)
      if (st%phase /= phase_stick .and. dev%p*dev%mu == 0.0_dp) then
         if (dev%p*largest_mu(dev) == 0.0_dp) st%phase = phase_stick
      end if
      changed = st%phase /= old
      st%centre = s
      ! with a constant mu the coefficients change with the phase only (a division a device
      ! a step less); a velocity-dependent mu follows sdot at every step
      if (changed .or. dev%mu_law /= mu_constant) call set_coefficients(dev, sdot, st)
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

   !> The state in which to take a step that ends in st1's phase (`refinement = 'implicit'`),
   !> from the state at its start st0, for a device whose phase changes (friction_settle keeps
   !> the others): the coefficients of the phase it ends in (st1: the band's
   !> coupling, or the sliding force with mu at the velocity the update was given, which the
   !> step then iterates to the velocity at its own end).
   !> A reversal, slip to the opposite slip, passed through the band within the step and is not
   !> taken in one phase (can = .false.): the force would reverse at the step's start.
   pure subroutine velocity_settle(st0, st1, st, can)
      type(device_state), intent(in) :: st0     !! state at the step's start
      type(device_state), intent(in) :: st1     !! the update's state at the step's end
      type(device_state), intent(out) :: st     !! state to take the step in
      logical, intent(out) :: can               !! the step can be taken in one phase

      st = st1
      can = st0%phase == phase_stick .or. st1%phase == phase_stick
   end subroutine velocity_settle

   !> The constant force of the phase st at the relative velocity sdot at the step's end: a
   !> sliding device with a speed-dependent mu, P mu(|sdot|) in the phase's direction; any
   !> other, st%f0 as it is. The fixed point f0 = velocity_follow(dev, sdot(f0), st) is the
   !> implicit step the time-step loop takes (fd_newmark's follow_forces).
   elemental real(dp) function velocity_follow(dev, sdot, st) result(f0)
      type(device_type), intent(in) :: dev   !! device parameters
      real(dp), intent(in) :: sdot           !! relative velocity at the step's end [m/s]
      type(device_state), intent(in) :: st   !! phase during the step

      f0 = st%f0
      if (dev%mu_law /= mu_constant .and. st%phase /= phase_stick) f0 = st%phase*dev%p*sliding_mu(dev, sdot)
   end function velocity_follow

   !> Force coefficients of the phase: the band's coupling P mu(eps) / eps, or the sliding
   !> force P mu(|sdot|) sgn with sdot the velocity at the start of the step (the step's
   !> first guess: the loop iterates it to the velocity at the step's end).
   pure subroutine set_coefficients(dev, sdot, st)
      type(device_type), intent(in) :: dev
      real(dp), intent(in) :: sdot
      type(device_state), intent(inout) :: st

      st%ks = 0.0_dp
      if (dev%mu_law == mu_constant) then
         if (st%phase == phase_stick) then
            st%cs = dev%p*dev%mu/dev%eps
            st%f0 = 0.0_dp
         else
            st%cs = 0.0_dp
            st%f0 = st%phase*dev%p*dev%mu
         end if
      else if (st%phase == phase_stick) then
         st%cs = dev%p*sliding_mu(dev, dev%eps)/dev%eps
         st%f0 = 0.0_dp
      else
         st%cs = 0.0_dp
         st%f0 = st%phase*dev%p*sliding_mu(dev, sdot)
      end if
   end subroutine set_coefficients

end module fd_friction_velocity
