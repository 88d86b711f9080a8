!> The hysteretic model of friction (Dimova, eqs. 2-5, Fig. 2): elastic-perfectly-plastic
!> force against relative displacement with stiffness k = P mu / f while sticking, the
!> constant force P mu sgn(sdot) while sliding. Correctness condition: eq. 12.
!>
!> Sliding starts when |F| reaches P mu (eqs. 3-4); the centre of the elastic range moves
!> with the plastic slip so that F stays continuous. Sliding ends at the turn of sdot (eq. 1,
!> the extremum of s), located to the step: an armed slide (|sdot| has reached eps1 in this
!> sliding phase) sticks in the step whose sdot has turned within the band |sdot| < eps1
!> (eq. 2); one whose sdot enters the band still along the slide goes on, unarmed (ended
!> there, its residual velocity carried the elastic force past P mu within a step: a
!> one-step stick, two transitions for one stop). An unarmed slide (the onset, where |sdot|
!> is far below eps1 and eq. 2 read literally would end it at once) ends when sdot turns
!> against the sliding direction. An armed slide whose velocity crossed the whole band
!> within one step reverses. docs/theory.md section 5.2.
module fd_friction_hysteretic
   use fd_kinds, only: dp
   use fd_model, only: device_type
   use fd_device_state, only: device_state, phase_stick, phase_slip_pos, phase_slip_neg, &
                              law_traits_type, stuck_spring
   implicit none
   private

   public :: hysteretic_init, hysteretic_update, hysteretic_correct, hysteretic_settle
   public :: hysteretic_energy, hysteretic_traits, hysteretic_stiffness, hysteretic_holds

contains

   !> What the hysteretic law says of itself: while it sticks, a spring k = P mu / f (eq. 3, set
   !> by f) that may ring; its slides end in the band |sdot| < eps1; Newmark checks eq. 12 in
   !> its armed slides; its spring stores elastic energy.
   pure function hysteretic_traits() result(traits)
      type(law_traits_type) :: traits   !! the hysteretic law's traits

      traits = law_traits_type(stuck=stuck_spring, band_name='eps1', coupling_name='f', checks_correctness=.true., &
                               checks_stick_ringing=.true., stores_energy=.true.)
   end function hysteretic_traits

   !> The sticking spring k = P mu / f (eq. 3) [N/m]; 0 for a device with P mu = 0 (no
   !> friction capacity, no force).
   elemental real(dp) function hysteretic_stiffness(dev) result(k)
      type(device_type), intent(in) :: dev     !! device parameters

      k = 0.0_dp
      if (dev%p*dev%mu > 0.0_dp) k = dev%p*dev%mu/dev%f
   end function hysteretic_stiffness

   !> Whether a sticking device holds its nodes together (through its spring): P mu > 0.
   elemental logical function hysteretic_holds(dev) result(holds)
      type(device_type), intent(in) :: dev     !! device parameters

      holds = dev%p*dev%mu > 0.0_dp
   end function hysteretic_holds

   !> Elastic energy stored in the device's spring: F^2 / (2 k) with k = P mu / f, in either
   !> phase (eq. 3: sliding, the spring holds P mu; it is released only when the force falls).
   elemental real(dp) function hysteretic_energy(dev, st, s) result(e)
      type(device_type), intent(in) :: dev     !! device parameters
      type(device_state), intent(in) :: st     !! its state
      real(dp), intent(in) :: s                !! relative displacement [m]
      real(dp) :: k, force

      e = 0.0_dp
      k = hysteretic_stiffness(dev)
      if (k <= 0.0_dp) return
      force = st%ks*s + st%f0          ! no damping in the law: the spring's force
      e = 0.5_dp*force*force/k
   end function hysteretic_energy

   !> A run starts sticking with no force, or sliding if the initial relative velocity is
   !> already outside the band |sdot| < eps1.
   pure subroutine hysteretic_init(dev, s, sdot, st)
      type(device_type), intent(in) :: dev   !! device parameters
      real(dp), intent(in) :: s              !! relative displacement [m]
      real(dp), intent(in) :: sdot           !! relative velocity [m/s]
      type(device_state), intent(out) :: st  !! initial state

      st%phase = phase_stick
      st%centre = s
      st%armed = .false.
      if (abs(sdot) >= dev%eps1 .and. dev%p*dev%mu > 0.0_dp) then
         st%phase = merge(phase_slip_pos, phase_slip_neg, sdot > 0.0_dp)
         st%centre = s - st%phase*dev%f
         st%armed = .true.
      end if
      call set_coefficients(dev, st)
   end subroutine hysteretic_init

   !> Phase for the next step from the state at the end of this one (eqs. 2-4). st comes from
   !> hysteretic_init or an earlier update: its coefficients (ks = P mu / f while sticking)
   !> are those of its phase.
   pure subroutine hysteretic_update(dev, s, sdot, st, changed)
      type(device_type), intent(in) :: dev      !! device parameters
      real(dp), intent(in) :: s                 !! relative displacement [m]
      real(dp), intent(in) :: sdot              !! relative velocity [m/s]
      type(device_state), intent(inout) :: st   !! state, updated
      logical, intent(out) :: changed           !! the phase changed
      real(dp) :: force, slip
      integer :: old

      old = st%phase
      slip = dev%p*dev%mu
      if (slip == 0.0_dp) then
         ! no friction capacity: F = 0 (k = 0), never slips
      else if (st%phase == phase_stick) then
         force = st%ks*(s - st%centre)                           ! st%ks: hysteretic_stiffness
         if (abs(force) >= slip) then
            st%phase = merge(phase_slip_pos, phase_slip_neg, force > 0.0_dp)
            st%armed = abs(sdot) >= dev%eps1
         end if
      else if (st%armed) then
         if (abs(sdot) < dev%eps1) then
            if (sdot*st%phase > 0.0_dp) then
               ! in the band, still along the slide: the slide goes on to its turn (eq. 1),
               ! unarmed. Ended here (eq. 2 read literally), the residual velocity carried
               ! the elastic force past P mu within a step: a one-step stick, and two
               ! transitions counted for one stop
               st%armed = .false.
            else
               st%phase = phase_stick                             ! eq. 2, at the turn
            end if
         else if (sdot*st%phase < 0.0_dp) then
            st%phase = -st%phase                                  ! crossed the band: reverse
         end if
      else
         if (sdot*st%phase <= 0.0_dp) then
            st%phase = phase_stick                                ! turned before reaching eps1
         else if (abs(sdot) >= dev%eps1) then
            st%armed = .true.
         end if
      end if
      changed = st%phase /= old
      if (st%phase /= phase_stick) then
         ! plastic slip: the elastic range follows so that |F| = P mu
         st%centre = s - st%phase*dev%f
      else if (changed) then
         ! end of sliding: F stays continuous at P mu sgn
         st%centre = s - old*dev%f
         st%armed = .false.
      end if
      ! the coefficients change with the phase only: while sliding the force is P mu sgn
      ! whatever the centre, while sticking the centre stays (a division a device a step less)
      if (changed) call set_coefficients(dev, st)
   end subroutine hysteretic_update

   !> Correctness condition, eq. 12, for a step taken in the phase st: checked in an armed
   !> slide (the unarmed start of a slide ends by the sign rule instead).
   pure logical function hysteretic_correct(dev, n, st, sdot_old, sdot_new) result(ok)
      type(device_type), intent(in) :: dev   !! device parameters
      real(dp), intent(in) :: n              !! n > 1 of eq. 12
      type(device_state), intent(in) :: st   !! phase during the step
      real(dp), intent(in) :: sdot_old       !! relative velocity at t - dt [m/s]
      real(dp), intent(in) :: sdot_new       !! relative velocity at t [m/s]

      ok = .true.
      if (st%phase /= phase_stick .and. st%armed) &
         ok = sdot_new*sdot_old > dev%eps1**2*(1.0_dp - 1.0_dp/n)
   end function hysteretic_correct

   !> The state in which to take a step that ends in st1's phase (`refinement = 'implicit'`),
   !> from the state at its start st0, for a device whose phase changes (friction_settle keeps
   !> the others): the elastic-perfectly-plastic return mapping. sdot is the relative
   !> velocity at the end of the last trial.
   !> - A slide that starts: the constant force P mu sgn of st1, unarmed (eq. 12 compares the
   !>   velocities at the two ends of a step inside a slide; this step starts sticking).
   !> - A slide that ends within the band: the step in the slide itself, st0; the sticking
   !>   state after it (hysteretic_update) keeps the force P mu sgn continuous at the step's
   !>   end.
   !> - A reversal (an armed slide whose velocity crossed the band), or a slide that ends with
   !>   its velocity turned beyond the band (an unarmed slide ends at any turn), is not taken
   !>   in one phase (can = .false.): the velocity passed through the band, where the device
   !>   may stick, and neither the slide's force nor the opposite one holds through the step.
   pure subroutine hysteretic_settle(dev, sdot, st0, st1, st, can)
      type(device_type), intent(in) :: dev      !! device parameters
      real(dp), intent(in) :: sdot              !! relative velocity at the last trial's end [m/s]
      type(device_state), intent(in) :: st0     !! state at the step's start
      type(device_state), intent(in) :: st1     !! the update's state at the step's end
      type(device_state), intent(out) :: st     !! state to take the step in
      logical, intent(out) :: can               !! the step can be taken in one phase

      can = .true.
      st = st0
      if (st0%phase == phase_stick) then
         st = st1
         st%armed = .false.
      else if (st1%phase /= phase_stick) then
         can = .false.
      else
         can = sdot*st0%phase > -dev%eps1
      end if
   end subroutine hysteretic_settle

   pure subroutine set_coefficients(dev, st)
      type(device_type), intent(in) :: dev
      type(device_state), intent(inout) :: st
      real(dp) :: k

      st%cs = 0.0_dp
      if (st%phase == phase_stick) then
         k = hysteretic_stiffness(dev)
         st%ks = k
         st%f0 = -k*st%centre
      else
         st%ks = 0.0_dp
         st%f0 = st%phase*dev%p*dev%mu
      end if
   end subroutine set_coefficients

end module fd_friction_hysteretic
