!> The one place that branches on the friction law. Each law is one module that says what it
!> is (`<law>_traits`: how it sticks, its band, the checks that apply, the energy it stores) and
!> gives its elemental kernels (init, update, correct, settle; its sticking stiffness or
!> damping, whether it holds when stuck, its capacity, its energy); every routine here is one
!> `select case` over the laws that calls them (as OpenSees's FrictionModel interface).
!> Adding a law is that module, its row in fd_names' law table and one case in each
!> `select case` below. A regularized law with no case here is an error at the start of a
!> Newmark run (friction_init), never a device without force.
module fd_friction
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int
   use fd_names, only: law_velocity, law_hysteretic, law_coulomb, law_name
   use fd_model, only: device_type, mu_constant, device_parameter
   use fd_device_state, only: device_state, law_traits_type, &
                              stuck_none, stuck_rigid, stuck_spring, stuck_dashpot
   use fd_friction_velocity, only: velocity_init, velocity_update, velocity_correct, velocity_settle, velocity_follow, &
                                   velocity_traits, velocity_damping, velocity_holds, velocity_capacity
   use fd_friction_hysteretic, only: hysteretic_init, hysteretic_update, hysteretic_correct, hysteretic_settle, &
                                     hysteretic_energy, hysteretic_traits, hysteretic_stiffness, hysteretic_holds
   use fd_friction_coulomb, only: coulomb_traits, coulomb_holds
   use fd_friction_planar, only: planar_velocity_update, planar_velocity_init, planar_velocity_correct, &
                                 planar_velocity_follow, planar_velocity_settle, planar_hysteretic_update, &
                                 planar_hysteretic_init, planar_hysteretic_correct, planar_hysteretic_settle
   implicit none
   private

   public :: friction_init, friction_step, friction_settle
   public :: follows_velocity, friction_follow, friction_energy
   ! what a law says of itself (law_traits) and of a device of it
   public :: law_traits_type, law_traits, stuck_none, stuck_rigid, stuck_spring, stuck_dashpot
   public :: law_stuck, law_band_name, law_coupling_name, law_checks_band_alternation, law_mu_of_speed
   public :: sticking_stiffness, sticking_damping, holds_when_stuck, links_when_stuck, friction_capacity, law_band

contains

   ! ---------------------------------------------------------------- what a law is

   !> The traits of a law (the default record, all .false., for an id without a case).
   elemental function law_traits(law) result(traits)
      integer, intent(in) :: law             !! law id (fd_names)
      type(law_traits_type) :: traits        !! what it says of itself

      select case (law)
      case (law_velocity)
         traits = velocity_traits()
      case (law_hysteretic)
         traits = hysteretic_traits()
      case (law_coulomb)
         traits = coulomb_traits()
      case default
         traits = law_traits_type()
      end select
   end function law_traits

   !> How a sticking device of the law joins the stuck system: stuck_rigid, stuck_spring,
   !> stuck_dashpot (stuck_none for an id without a case).
   elemental integer function law_stuck(law) result(stuck)
      integer, intent(in) :: law             !! law id

      associate (t => law_traits(law))
         stuck = t%stuck
      end associate
   end function law_stuck

   !> The &friction variable of the law's band ('eps', 'eps1'; blank for a law without one).
   elemental function law_band_name(law) result(name)
      integer, intent(in) :: law             !! law id
      character(len=4) :: name               !! the variable's name, left-adjusted

      associate (t => law_traits(law))
         name = t%band_name
      end associate
   end function law_band_name

   !> The &friction variable that sets the law's sticking coupling ('eps' for the band's
   !> dashpot, 'f' for the hysteretic spring; blank for a law without one).
   elemental function law_coupling_name(law) result(name)
      integer, intent(in) :: law             !! law id
      character(len=4) :: name               !! the variable's name, left-adjusted

      associate (t => law_traits(law))
         name = t%coupling_name
      end associate
   end function law_coupling_name

   !> Whether the law's band force may alternate from step to step (fd_band_alternation).
   elemental logical function law_checks_band_alternation(law) result(checks)
      integer, intent(in) :: law             !! law id

      associate (t => law_traits(law))
         checks = t%checks_band_alternation
      end associate
   end function law_checks_band_alternation

   !> Whether the law's mu may depend on the sliding speed (mu_law other than 'constant').
   elemental logical function law_mu_of_speed(law) result(speed)
      integer, intent(in) :: law             !! law id

      associate (t => law_traits(law))
         speed = t%mu_of_speed
      end associate
   end function law_mu_of_speed

   ! ---------------------------------------------------------------- what a device of it is

   !> The sticking spring of a device [N/m]: k = P mu / f of a device whose law sticks through
   !> a spring (traits stuck_spring: the hysteretic law, eq. 3); 0 for the others (a
   !> velocity-law device sticks through a dashpot, a Coulomb one rigidly). The stuck system's
   !> modes and stiffness, the step limits, the step checks and the stick ringing take it from here.
   elemental real(dp) function sticking_stiffness(dev) result(k)
      type(device_type), intent(in) :: dev   !! the device

      k = 0.0_dp
      if (law_stuck(dev%law) == stuck_spring) k = sticking_coupling(dev)
   end function sticking_stiffness

   !> The sticking dashpot of a device [N s/m]: the band coupling P mu(eps) / eps of a device
   !> whose law sticks through a dashpot (traits stuck_dashpot: the velocity law, eq. 6); 0
   !> for the others.
   elemental real(dp) function sticking_damping(dev) result(c)
      type(device_type), intent(in) :: dev   !! the device

      c = 0.0_dp
      if (law_stuck(dev%law) == stuck_dashpot) c = sticking_coupling(dev)
   end function sticking_damping

   !> The coupling through which a sticking device holds, of the kind its law's traits say
   !> (law_stuck): the hysteretic law's spring [N/m], the velocity law's band dashpot [N s/m];
   !> 0 for a law that sticks rigidly or has no case.
   elemental real(dp) function sticking_coupling(dev) result(x)
      type(device_type), intent(in) :: dev   !! the device

      select case (dev%law)
      case (law_hysteretic)
         x = hysteretic_stiffness(dev)
      case (law_velocity)
         x = velocity_damping(dev)
      case default
         x = 0.0_dp
      end select
   end function sticking_coupling

   !> Whether a device holds its nodes together while it sticks (a link of the stuck system,
   !> or its spring): each law says (a velocity-law device through P mu(eps) > 0, the others
   !> with P mu > 0); .false. for a law without a case.
   elemental logical function holds_when_stuck(dev) result(holds)
      type(device_type), intent(in) :: dev   !! the device

      select case (dev%law)
      case (law_velocity)
         holds = velocity_holds(dev)
      case (law_hysteretic)
         holds = hysteretic_holds(dev)
      case (law_coulomb)
         holds = coulomb_holds(dev)
      case default
         holds = .false.
      end select
   end function holds_when_stuck

   !> Whether a sticking device is a rigid link of the stuck system's groups: it holds, and
   !> not through a spring (which the stuck stiffness carries instead).
   elemental logical function links_when_stuck(dev) result(links)
      type(device_type), intent(in) :: dev   !! the device

      links = holds_when_stuck(dev)
      if (links) links = law_stuck(dev%law) /= stuck_spring
   end function links_when_stuck

   !> The friction capacity of a device, P times the largest mu at any sliding speed [N]: a
   !> device with none never slips.
   elemental real(dp) function friction_capacity(dev) result(cap)
      type(device_type), intent(in) :: dev   !! the device

      select case (dev%law)
      case (law_velocity)
         cap = velocity_capacity(dev)
      case default
         cap = dev%p*dev%mu
      end select
   end function friction_capacity

   !> The band of a device [m/s]: the value of its law's band variable (law_band_name: eps of
   !> the velocity law, eps1 of the hysteretic law); 0 for a law without one.
   elemental real(dp) function law_band(dev) result(band)
      type(device_type), intent(in) :: dev   !! the device

      band = device_parameter(dev, law_band_name(dev%law))
   end function law_band

   ! ---------------------------------------------------------------- the time step

   !> After a trial step, for every device: the phase for the next step (st1, from st at
   !> the trial state s1, sd1) and the correctness condition of the step (eqs. 9, 12), with
   !> whether any phase changed and any device violates the condition: each law's update and
   !> correctness condition device by device, in one loop that calls each law's routines
   !> directly (the time step's per-device cost in a large structure; explicit shapes, since
   !> building array descriptors at every call cost more than a two-mass model's laws). A
   !> law with no case here keeps its state (friction_init rejected it before the first step).
   subroutine friction_step(nd, dev, n, s1, sd1, sd, st, st1, changed, ok, any_changed, any_bad)
      integer, intent(in) :: nd                 !! devices
      type(device_type), intent(in) :: dev(nd)  !! devices
      real(dp), intent(in) :: n                 !! n > 1 of the correctness condition
      real(dp), intent(in) :: s1(nd)            !! relative displacements at the step's end [m]
      real(dp), intent(in) :: sd1(nd)           !! relative velocities at the step's end [m/s]
      real(dp), intent(in) :: sd(nd)            !! relative velocities at its start [m/s]
      type(device_state), intent(in) :: st(nd)  !! states during the step
      type(device_state), intent(inout) :: st1(nd) !! states for the next step
      logical, intent(out) :: changed(nd)       !! the phase changed
      logical, intent(out) :: ok(nd)            !! the step satisfies the condition
      logical, intent(out) :: any_changed       !! some phase changed
      logical, intent(out) :: any_bad           !! some device violates the condition
      integer :: d
      logical :: some_changed, some_bad          ! locals: the dummies would be stored at every device

      some_changed = .false.
      some_bad = .false.
      do d = 1, nd
         if (dev(d)%partner > 0) then
            ! a planar bearing: its two components together, once
            if (dev(d)%partner < d) cycle
            call planar_step(dev(d), n, [d, dev(d)%partner], s1, sd1, sd, st, st1, changed, ok)
            some_changed = some_changed .or. changed(d) .or. changed(dev(d)%partner)
            some_bad = some_bad .or. .not. ok(d)
            cycle
         end if
         st1(d) = st(d)
         select case (dev(d)%law)
         case (law_hysteretic)
            call hysteretic_update(dev(d), s1(d), sd1(d), st1(d), changed(d))
            ok(d) = hysteretic_correct(dev(d), n, st(d), sd(d), sd1(d))
         case (law_velocity)
            call velocity_update(dev(d), s1(d), sd1(d), st1(d), changed(d))
            ok(d) = velocity_correct(dev(d), n, st(d), sd(d), sd1(d))
         case default
            changed(d) = .false.
            ok(d) = .true.
         end select
         some_changed = some_changed .or. changed(d)
         some_bad = some_bad .or. .not. ok(d)
      end do
      any_changed = some_changed
      any_bad = some_bad
   end subroutine friction_step

   !> friction_step for a planar bearing, the devices pq = (x, y) components: the phases for the
   !> next step and the correctness condition on the resultant (fd_friction_planar), the same
   !> verdict for both components.
   pure subroutine planar_step(dev, n, pq, s1, sd1, sd, st, st1, changed, ok)
      type(device_type), intent(in) :: dev      !! the bearing's parameters (its x component)
      real(dp), intent(in) :: n                 !! n > 1 of the correctness condition
      integer, intent(in) :: pq(2)              !! its two devices
      real(dp), intent(in) :: s1(:), sd1(:), sd(:)
      type(device_state), intent(in) :: st(:)
      type(device_state), intent(inout) :: st1(:)
      logical, intent(inout) :: changed(:), ok(:)
      type(device_state) :: pair(2), pair0(2)
      real(dp) :: x1(2), v1(2), v0(2)
      logical :: ch(2), good

      ! local copies: no array temporary for a vector subscript in a call
      pair0 = st(pq)
      pair = pair0
      x1 = s1(pq)
      v1 = sd1(pq)
      v0 = sd(pq)
      good = .true.
      select case (dev%law)
      case (law_hysteretic)
         call planar_hysteretic_update(dev, x1, v1, pair, ch)
         good = planar_hysteretic_correct(dev, n, pair0, v0, v1)
      case (law_velocity)
         call planar_velocity_update(dev, x1, v1, pair, ch)
         good = planar_velocity_correct(dev, n, pair0, v0, v1)
      case default
         ch = .false.
      end select
      st1(pq) = pair
      changed(pq) = ch
      ok(pq) = good
   end subroutine planar_step


   !> `refinement = 'implicit'`: the state of every device in which to take a step that ends
   !> in the phases of st1 (the law's update at the end of the last trial, where the relative
   !> velocities were sd1), from the states at its start st0; can is .false. when a device's
   !> change cannot be taken in one phase (the step is then refined). A device that keeps its
   !> phase keeps st0; each law says the rest (hysteretic_settle, velocity_settle).
   subroutine friction_settle(nd, dev, sd1, st0, st1, st, can)
      integer, intent(in) :: nd                 !! devices
      type(device_type), intent(in) :: dev(nd)  !! devices
      real(dp), intent(in) :: sd1(nd)           !! relative velocities at the last trial's end [m/s]
      type(device_state), intent(in) :: st0(nd) !! states at the step's start
      type(device_state), intent(in) :: st1(nd) !! the update's states at the step's end
      type(device_state), intent(inout) :: st(nd) !! states to take the step in
      logical, intent(out) :: can               !! every change can be taken in one phase
      logical :: ok
      integer :: d

      can = .true.
      do d = 1, nd
         if (dev(d)%partner > 0) then
            if (dev(d)%partner < d) cycle
            call planar_settle(dev(d), [d, dev(d)%partner], sd1, st0, st1, st, ok)
            can = can .and. ok
            cycle
         end if
         if (st1(d)%phase == st0(d)%phase) then
            st(d) = st0(d)
            cycle
         end if
         select case (dev(d)%law)
         case (law_hysteretic)
            call hysteretic_settle(dev(d), sd1(d), st0(d), st1(d), st(d), ok)
         case (law_velocity)
            call velocity_settle(st0(d), st1(d), st(d), ok)
         case default
            st(d) = st0(d)
            ok = .false.
         end select
         can = can .and. ok
      end do
   end subroutine friction_settle

   !> friction_settle for a planar bearing, the devices pq = (x, y): both keep their start's
   !> states when neither changes phase, else the law's planar settle decides for both.
   pure subroutine planar_settle(dev, pq, sd1, st0, st1, st, can)
      type(device_type), intent(in) :: dev      !! the bearing's parameters (its x component)
      integer, intent(in) :: pq(2)              !! its two devices
      real(dp), intent(in) :: sd1(:)
      type(device_state), intent(in) :: st0(:), st1(:)
      type(device_state), intent(inout) :: st(:)
      logical, intent(out) :: can
      type(device_state) :: pair(2), pair0(2), pair1(2)
      real(dp) :: v1(2)

      can = .true.
      pair0 = st0(pq)
      pair1 = st1(pq)
      v1 = sd1(pq)
      if (pair1(1)%phase == pair0(1)%phase .and. pair1(2)%phase == pair0(2)%phase) then
         st(pq) = pair0
         return
      end if
      select case (dev%law)
      case (law_hysteretic)
         call planar_hysteretic_settle(dev, v1, pair0, pair1, pair, can)
      case (law_velocity)
         call planar_velocity_settle(pair0, pair1, pair, can)
      case default
         pair = pair0
         can = .false.
      end select
      st(pq) = pair
   end subroutine planar_settle

   !> Elastic energy a device stores at relative displacement s in its state [J] (a law whose
   !> traits say stores_energy: the hysteretic law's spring; the velocity law stores none: its
   !> band is a dashpot).
   elemental real(dp) function friction_energy(dev, st, s) result(e)
      type(device_type), intent(in) :: dev      !! device parameters
      type(device_state), intent(in) :: st      !! its state
      real(dp), intent(in) :: s                 !! relative displacement [m]

      select case (dev%law)
      case (law_hysteretic)
         e = hysteretic_energy(dev, st, s)
      case default
         e = 0.0_dp
      end select
   end function friction_energy

   !> Whether a device's sliding force depends on the velocity within a step (a device of a law
   !> whose mu may depend on the sliding speed, law_mu_of_speed, with a mu_law that does): the
   !> time-step loop iterates such forces to the velocity at the step's end (friction_follow).
   elemental logical function follows_velocity(dev) result(follows)
      type(device_type), intent(in) :: dev      !! device parameters

      follows = law_mu_of_speed(dev%law)
      if (follows) follows = dev%mu_law /= mu_constant
   end function follows_velocity

   !> For the devices fl(1:nf) (those follows_velocity picks), the change df of their constant
   !> force f0 that the relative velocities sd1 at the step's end ask for: each law's own force
   !> at sd1 in the phase st minus st%f0 (velocity_follow). Nothing is changed.
   pure subroutine friction_follow(nf, fl, dev, sd1, st, df)
      integer, intent(in) :: nf                 !! devices followed
      integer, intent(in) :: fl(nf)             !! their numbers
      type(device_type), intent(in) :: dev(:)   !! all devices
      real(dp), intent(in) :: sd1(:)            !! relative velocities at the step's end [m/s]
      type(device_state), intent(in) :: st(:)   !! states during the step
      real(dp), intent(out) :: df(nf)           !! the change of each one's f0 [N]
      integer :: q, d

      do q = 1, nf
         d = fl(q)
         select case (dev(d)%law)
         case (law_velocity)
            if (dev(d)%partner > 0) then
               ! a planar bearing's component: mu at the resultant speed, along its direction
               df(q) = planar_follow(dev, d, sd1, st) - st(d)%f0
            else
               df(q) = velocity_follow(dev(d), sd1(d), st(d)) - st(d)%f0
            end if
         case default
            df(q) = 0.0_dp
         end select
      end do
   end subroutine friction_follow

   !> The velocity law's sliding force of component d of a planar bearing at the velocities sd1
   !> (planar_velocity_follow, the bearing's parameters those of its x component).
   pure real(dp) function planar_follow(dev, d, sd1, st) result(f0)
      type(device_type), intent(in) :: dev(:)   !! all devices
      integer, intent(in) :: d                  !! the component
      real(dp), intent(in) :: sd1(:)            !! relative velocities [m/s]
      type(device_state), intent(in) :: st(:)   !! states during the step
      type(device_state) :: pair(2)
      real(dp) :: v1(2)
      integer :: pq(2)

      pq = [d, dev(d)%partner]
      if (dev(d)%component == 2) pq = [dev(d)%partner, d]
      pair = st(pq)
      v1 = sd1(pq)
      f0 = planar_velocity_follow(dev(pq(1)), v1, pair, dev(d)%component)
   end function planar_follow

   !> Initial phase and force coefficients of every device; an error for a device whose
   !> law has no case here.
   subroutine friction_init(dev, s, sdot, st, error)
      type(device_type), intent(in) :: dev(:)   !! devices
      real(dp), intent(in) :: s(:)              !! relative displacements [m]
      real(dp), intent(in) :: sdot(:)           !! relative velocities [m/s]
      type(device_state), intent(out) :: st(:)  !! initial states
      type(error_type), allocatable, intent(out) :: error !! a law without a case here
      integer :: d

      do d = 1, size(dev)
         if (dev(d)%partner > 0) then
            if (dev(d)%partner > d) call planar_init(dev(d), [d, dev(d)%partner], s, sdot, st)
            if (dev(d)%law == law_velocity .or. dev(d)%law == law_hysteretic) cycle
         end if
         select case (dev(d)%law)
         case (law_velocity)
            call velocity_init(dev(d), s(d), sdot(d), st(d))
         case (law_hysteretic)
            call hysteretic_init(dev(d), s(d), sdot(d), st(d))
         case default
            call fatal_error(error, "device "//trim(fmt_int(d))//": friction law '"//trim(law_name(dev(d)%law))// &
                             "' (id "//trim(fmt_int(dev(d)%law))//") is not a law the Newmark technique integrates")
            return
         end select
      end do
   end subroutine friction_init

   !> Initial states of a planar bearing's components pq = (x, y).
   pure subroutine planar_init(dev, pq, s, sdot, st)
      type(device_type), intent(in) :: dev      !! the bearing's parameters (its x component)
      integer, intent(in) :: pq(2)              !! its two devices
      real(dp), intent(in) :: s(:), sdot(:)
      type(device_state), intent(inout) :: st(:)
      type(device_state) :: pair(2)
      real(dp) :: x(2), v(2)

      x = s(pq)
      v = sdot(pq)
      select case (dev%law)
      case (law_hysteretic)
         call planar_hysteretic_init(dev, x, v, pair)
         st(pq) = pair
      case (law_velocity)
         call planar_velocity_init(dev, x, v, pair)
         st(pq) = pair
      end select
   end subroutine planar_init


end module fd_friction
