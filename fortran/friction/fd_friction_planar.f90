!> The paper's two laws in the plane, for a planar bearing: two devices (its components along
!> x and y, each with its own direction b) that know each other (device_type's partner). A
!> component keeps the one-dimensional form F = ks s + cs s' + f0 (fd_device_state), so the
!> time-step loop, the outputs, the energy and the checks see two ordinary devices; only the
!> phase, the sliding direction and the correctness condition are decided on the resultant.
!>
!> - Velocity law: F = c1 v inside the disc |v| < eps (each component its dashpot
!>   c1 = P mu(eps) / eps), F = P mu(|v|) v/|v| outside, the direction that of the velocity at
!>   the previous step's end (the 1D law's sign, eq. 8). Correctness condition on the
!>   resultant: v(t).v(t - dt) > eps^2 (1 - 1/n).
!> - Hysteretic law: elastic-perfectly-plastic with the circular yield surface |F| <= P mu,
!>   the sticking spring k = P mu / f on each component, radial return (the trial force
!>   k (s - centre) brought back onto the circle along itself), the end of sliding at
!>   |v| < eps1 with the velocity turned against the sliding direction (v.d <= 0), the 1D
!>   law's arming rule with |v| for |s'|. Correctness condition: v(t).v(t - dt) > eps1^2 (1 - 1/n)
!>   in an armed slide.
!>
!> A component's phase is stick while the bearing sticks, and the sign of its component of the
!> sliding direction (d_x, d_y; st%dir) while it slides; a component with d = 0 keeps the sign
!> it had (slip + at the start of a slide). For motion along one axis every operation is the
!> one-dimensional law's (hypot(x, 0) = |x|, x/|x| = +-1, a + 0 = a): the same numbers to the
!> bit (docs/theory.md, "Planar bearings").
!>
!> A normal force that varies (docs/theory.md, "Varying normal force"): the time-step loop
!> hands the kernels the bearing with p its current normal force N (max(N, 0)) and p_static
!> the N0 whose pendulum stiffness N0 / R the structure's K holds. The friction is that of p
!> (P mu, the band's P mu / eps, the sticking spring P mu / f: the hysteretic law's yield
!> |s - c| >= f does not depend on P), and the pendulum's excess (p - p_static) / R s, at s of
!> the step's start, joins f0. p <= 0 (uplift): no friction and no restoring force.
module fd_friction_planar
   use fd_kinds, only: dp
   use fd_model, only: device_type, mu_constant, sliding_mu
   use fd_device_state, only: device_state, phase_stick, phase_slip_pos, phase_slip_neg
   use fd_friction_velocity, only: largest_mu
   implicit none
   private

   public :: planar_velocity_update, planar_velocity_init, planar_velocity_correct, planar_velocity_follow
   public :: planar_hysteretic_update, planar_hysteretic_init, planar_hysteretic_correct
   public :: planar_velocity_settle, planar_hysteretic_settle, pendulum_excess, normal_force, with_normal_force
   public :: devices_at_normal_force, normal_force_range

   real(dp), parameter :: g = 9.80665_dp   !! standard gravity [m/s2]

contains

   ! ---------------------------------------------------------------- velocity law

   !> Phase and coefficients of a bearing at the start of a run (velocity law).
   pure subroutine planar_velocity_init(dev, s, sd, st)
      type(device_type), intent(in) :: dev          !! the bearing's parameters (its x component)
      real(dp), intent(in) :: s(2)                  !! relative displacement (x, y) [m]
      real(dp), intent(in) :: sd(2)                 !! relative velocity (x, y) [m/s]
      type(device_state), intent(out) :: st(2)      !! initial states of its components
      logical :: changed(2)

      st(1)%phase = phase_stick
      st(2)%phase = phase_stick
      call planar_velocity_update(dev, s, sd, st, changed)
   end subroutine planar_velocity_init

   !> Phase for the next step from the velocity at the end of this one: stick inside the disc
   !> |v| < eps, else sliding along v/|v|; the force's coefficients of that phase (mu at |v|).
   pure subroutine planar_velocity_update(dev, s, sd, st, changed)
      type(device_type), intent(in) :: dev          !! the bearing's parameters
      real(dp), intent(in) :: s(2)                  !! relative displacement (x, y) [m]
      real(dp), intent(in) :: sd(2)                 !! relative velocity (x, y) [m/s]
      type(device_state), intent(inout) :: st(2)    !! states, updated
      logical, intent(out) :: changed(2)            !! each component's phase changed
      real(dp) :: speed, c, pmu, kp
      integer :: old(2), m
      logical :: slides

      old = st%phase
      speed = hypot(sd(1), sd(2))
      slides = .not. speed < dev%eps
      ! no friction capacity: F = 0, never slips
      if (slides .and. dev%p*dev%mu == 0.0_dp) slides = dev%p*largest_mu(dev) /= 0.0_dp
      if (slides) then
         pmu = dev%p*sliding_mu(dev, speed)
         if (dev%mu_law == mu_constant) pmu = dev%p*dev%mu
         do m = 1, 2
            st(m)%dir = sd(m)/speed
            st(m)%phase = slide_phase(st(m)%dir, old(m))
            st(m)%ks = 0.0_dp
            st(m)%cs = 0.0_dp
            st(m)%f0 = pmu*st(m)%dir
         end do
      else
         if (dev%mu_law == mu_constant) then
            c = dev%p*dev%mu/dev%eps
         else
            c = dev%p*sliding_mu(dev, dev%eps)/dev%eps
         end if
         do m = 1, 2
            st(m)%phase = phase_stick
            st(m)%dir = 0.0_dp
            st(m)%ks = 0.0_dp
            st(m)%cs = c
            st(m)%f0 = 0.0_dp
         end do
      end if
      kp = pendulum_excess(dev)
      do m = 1, 2
         st(m)%centre = s(m)
         if (kp /= 0.0_dp) st(m)%f0 = st(m)%f0 + kp*s(m)
         changed(m) = st(m)%phase /= old(m)
      end do
   end subroutine planar_velocity_update

   !> Correctness condition of a step taken sliding: v(t).v(t - dt) > eps^2 (1 - 1/n).
   pure logical function planar_velocity_correct(dev, n, st, sd_old, sd_new) result(ok)
      type(device_type), intent(in) :: dev          !! the bearing's parameters
      real(dp), intent(in) :: n                     !! n > 1
      type(device_state), intent(in) :: st(2)      !! phases during the step
      real(dp), intent(in) :: sd_old(2)             !! relative velocity at t - dt [m/s]
      real(dp), intent(in) :: sd_new(2)             !! relative velocity at t [m/s]

      ok = .true.
      if (st(1)%phase /= phase_stick) ok = sd_new(1)*sd_old(1) + sd_new(2)*sd_old(2) > dev%eps**2*(1.0_dp - 1.0_dp/n)
   end function planar_velocity_correct

   !> The constant force of component m in the phase st at the velocity sd at the step's end:
   !> sliding with a speed-dependent mu, P mu(|v|) d_m (and the pendulum's excess at the
   !> step's start, st%centre); otherwise st(m)%f0 as it is.
   pure real(dp) function planar_velocity_follow(dev, sd, st, m) result(f0)
      type(device_type), intent(in) :: dev          !! the bearing's parameters
      real(dp), intent(in) :: sd(2)                 !! relative velocity at the step's end [m/s]
      type(device_state), intent(in) :: st(2)      !! phases during the step
      integer, intent(in) :: m                      !! the component (1: x, 2: y)

      real(dp) :: kp

      f0 = st(m)%f0
      if (dev%mu_law /= mu_constant .and. st(m)%phase /= phase_stick) then
         f0 = dev%p*sliding_mu(dev, hypot(sd(1), sd(2)))*st(m)%dir
         kp = pendulum_excess(dev)
         if (kp /= 0.0_dp) f0 = f0 + kp*st(m)%centre
      end if
   end function planar_velocity_follow

   !> The states to take a step in that ends in st1's phases (`refinement = 'implicit'`): those
   !> of the end, unless the bearing slides at both ends in a direction that turned through a
   !> component's sign (the 1D law's reversal), which is not taken in one phase.
   pure subroutine planar_velocity_settle(st0, st1, st, can)
      type(device_state), intent(in) :: st0(2)      !! states at the step's start
      type(device_state), intent(in) :: st1(2)      !! the update's states at its end
      type(device_state), intent(out) :: st(2)      !! states to take the step in
      logical, intent(out) :: can                   !! the step can be taken in one phase

      st = st1
      can = st0(1)%phase == phase_stick .or. st1(1)%phase == phase_stick
   end subroutine planar_velocity_settle

   ! ---------------------------------------------------------------- hysteretic law

   !> A bearing starts sticking with no force, or sliding along v when |v| >= eps1.
   pure subroutine planar_hysteretic_init(dev, s, sd, st)
      type(device_type), intent(in) :: dev          !! the bearing's parameters
      real(dp), intent(in) :: s(2)                  !! relative displacement (x, y) [m]
      real(dp), intent(in) :: sd(2)                 !! relative velocity (x, y) [m/s]
      type(device_state), intent(out) :: st(2)      !! initial states
      real(dp) :: speed
      integer :: m

      speed = hypot(sd(1), sd(2))
      do m = 1, 2
         st(m)%phase = phase_stick
         st(m)%centre = s(m)
         st(m)%armed = .false.
         st(m)%dir = 0.0_dp
         if (speed >= dev%eps1 .and. dev%p*dev%mu > 0.0_dp) then
            st(m)%dir = sd(m)/speed
            st(m)%phase = slide_phase(st(m)%dir, phase_stick)
            st(m)%centre = s(m) - dev%f*st(m)%dir
            st(m)%armed = .true.
         end if
      end do
      call hysteretic_coefficients(dev, s, st)
   end subroutine planar_hysteretic_init

   !> Phase for the next step from the state at the end of this one: a sticking bearing
   !> slides when its elastic force reaches the circle |F| = P mu (along F); an armed slide
   !> sticks when |v| < eps1 with v turned (v.d <= 0) and goes on unarmed when still along d;
   !> one whose velocity crossed the disc in one step (v.d < 0, |v| >= eps1) slides along v;
   !> an unarmed slide sticks when v.d <= 0 and arms at |v| >= eps1. While sliding, the trial
   !> force k (s - centre) is returned radially onto the circle: d = its direction, and the
   !> centre follows so that k (s - centre) = P mu d.
   pure subroutine planar_hysteretic_update(dev, s, sd, st, changed)
      type(device_type), intent(in) :: dev          !! the bearing's parameters
      real(dp), intent(in) :: s(2)                  !! relative displacement (x, y) [m]
      real(dp), intent(in) :: sd(2)                 !! relative velocity (x, y) [m/s]
      type(device_state), intent(inout) :: st(2)    !! states, updated
      logical, intent(out) :: changed(2)            !! each component's phase changed
      real(dp) :: k, force(2), size_f, speed, along, dir0(2)
      integer :: old(2), m
      logical :: sticks, slides_now, armed

      old = st%phase
      changed = .false.
      if (dev%p <= 0.0_dp) then
         ! lifted off (a varying normal force at or below 0): no force; sticks, unloaded, when
         ! the bearing comes down again
         do m = 1, 2
            st(m)%phase = phase_stick
            st(m)%centre = s(m)
            st(m)%dir = 0.0_dp
            st(m)%armed = .false.
         end do
         call hysteretic_coefficients(dev, s, st)
         changed = st%phase /= old
         return
      end if
      if (dev%p*dev%mu == 0.0_dp) then
         ! no friction capacity: F = 0 (and the pendulum's excess), never slips
         call hysteretic_coefficients(dev, s, st)
         return
      end if
      k = dev%p*dev%mu/dev%f
      speed = hypot(sd(1), sd(2))
      dir0 = st%dir
      along = sd(1)*dir0(1) + sd(2)*dir0(2)
      armed = st(1)%armed
      sticks = old(1) == phase_stick
      slides_now = .false.
      if (sticks) then
         force = k*(s - st%centre)
         size_f = hypot(force(1), force(2))
         if (size_f >= dev%p*dev%mu) then
            slides_now = .true.
            sticks = .false.
            armed = speed >= dev%eps1
         end if
      else if (armed) then
         if (speed < dev%eps1) then
            if (along > 0.0_dp) then
               armed = .false.
            else
               sticks = .true.
            end if
         else if (along < 0.0_dp) then
            if (sd(1)*dir0(2) - sd(2)*dir0(1) == 0.0_dp) then
               ! along the slide's line: the velocity crossed the disc within a step (the 1D
               ! law's reversal): slides along v
               force = sd
               size_f = speed
               slides_now = .true.
            else
               ! turned against the force: the elastic unloading of the radial return
               sticks = .true.
            end if
         end if
      else
         if (.not. along > 0.0_dp) then
            sticks = .true.
         else if (speed >= dev%eps1) then
            armed = .true.
         end if
      end if
      if (sticks) then
         if (old(1) /= phase_stick) then
            ! end of sliding: the force stays P mu d
            do m = 1, 2
               st(m)%centre = s(m) - dev%f*dir0(m)
               st(m)%phase = phase_stick
               st(m)%dir = 0.0_dp
               st(m)%armed = .false.
            end do
         end if
         ! the sticking spring and the pendulum's excess of the current normal force
         call hysteretic_coefficients(dev, s, st)
      else
         if (.not. slides_now) then
            ! going on sliding: the radial return of the trial force
            force = k*(s - st%centre)
            size_f = hypot(force(1), force(2))
            if (size_f == 0.0_dp) then
               force = dir0
               size_f = 1.0_dp
            end if
         end if
         do m = 1, 2
            st(m)%dir = force(m)/size_f
            st(m)%phase = slide_phase(st(m)%dir, old(m))
            st(m)%centre = s(m) - dev%f*st(m)%dir
            st(m)%armed = armed
         end do
         call hysteretic_coefficients(dev, s, st)
      end if
      changed = st%phase /= old
   end subroutine planar_hysteretic_update

   !> Correctness condition in an armed slide: v(t).v(t - dt) > eps1^2 (1 - 1/n).
   pure logical function planar_hysteretic_correct(dev, n, st, sd_old, sd_new) result(ok)
      type(device_type), intent(in) :: dev          !! the bearing's parameters
      real(dp), intent(in) :: n                     !! n > 1
      type(device_state), intent(in) :: st(2)      !! phases during the step
      real(dp), intent(in) :: sd_old(2)             !! relative velocity at t - dt [m/s]
      real(dp), intent(in) :: sd_new(2)             !! relative velocity at t [m/s]

      ok = .true.
      if (st(1)%phase /= phase_stick .and. st(1)%armed) &
         ok = sd_new(1)*sd_old(1) + sd_new(2)*sd_old(2) > dev%eps1**2*(1.0_dp - 1.0_dp/n)
   end function planar_hysteretic_correct

   !> The states to take a step in that ends in st1's phases (`refinement = 'implicit'`), as
   !> the 1D law's: a slide that starts, in its sliding force, unarmed; one that ends, in the
   !> slide, when the velocity has not turned beyond the disc (v.d > -eps1); a slide at both
   !> ends whose phases differ (a component's sign turned) is not taken in one phase.
   pure subroutine planar_hysteretic_settle(dev, sd, st0, st1, st, can)
      type(device_type), intent(in) :: dev          !! the bearing's parameters
      real(dp), intent(in) :: sd(2)                 !! relative velocity at the last trial's end [m/s]
      type(device_state), intent(in) :: st0(2)      !! states at the step's start
      type(device_state), intent(in) :: st1(2)      !! the update's states at its end
      type(device_state), intent(out) :: st(2)      !! states to take the step in
      logical, intent(out) :: can                   !! the step can be taken in one phase

      can = .true.
      st = st0
      if (st0(1)%phase == phase_stick) then
         st = st1
         st%armed = .false.
      else if (st1(1)%phase /= phase_stick) then
         can = .false.
      else
         can = sd(1)*st0(1)%dir + sd(2)*st0(2)%dir > -dev%eps1
      end if
   end subroutine planar_hysteretic_settle

   ! ---------------------------------------------------------------- helpers

   !> A sliding component's phase: the sign of its direction, the old one kept for d = 0.
   elemental integer function slide_phase(dir, old) result(phase)
      real(dp), intent(in) :: dir                   !! its component of the sliding direction
      integer, intent(in) :: old                    !! its phase before

      if (dir > 0.0_dp) then
         phase = phase_slip_pos
      else if (dir < 0.0_dp) then
         phase = phase_slip_neg
      else if (old /= phase_stick) then
         phase = old
      else
         phase = phase_slip_pos
      end if
   end function slide_phase

   !> The hysteretic coefficients of each component's phase: ks = P mu / f, f0 = -k centre
   !> while sticking; the force P mu d while sliding; and the pendulum's excess at s.
   pure subroutine hysteretic_coefficients(dev, s, st)
      type(device_type), intent(in) :: dev
      real(dp), intent(in) :: s(2)
      type(device_state), intent(inout) :: st(2)
      real(dp) :: k, kp
      integer :: m

      k = max(dev%p, 0.0_dp)*dev%mu/dev%f
      kp = pendulum_excess(dev)
      do m = 1, 2
         st(m)%cs = 0.0_dp
         if (st(m)%phase == phase_stick) then
            st(m)%ks = k
            st(m)%f0 = -k*st(m)%centre
         else
            st(m)%ks = 0.0_dp
            st(m)%f0 = dev%p*dev%mu*st(m)%dir
         end if
         if (kp /= 0.0_dp) st(m)%f0 = st(m)%f0 + kp*s(m)
      end do
   end subroutine hysteretic_coefficients

   !> A bearing's normal force under the ground's vertical acceleration az (upward positive; the
   !> vertical support rigid): N = P (1 + az / g), P = p_static, the deck's p, plus dn, the
   !> overturning's share (fd_overturning; 0 when not given). N <= 0 is uplift.
   !> What every technique asks for a bearing's N at a time (az = table_acceleration of the
   !> vertical component then, dn = overturning_forces' of the state).
   elemental real(dp) function normal_force(dev, az, dn) result(n)
      type(device_type), intent(in) :: dev          !! the bearing (a component) as the deck made it
      real(dp), intent(in) :: az                    !! vertical ground acceleration [m/s2]
      real(dp), intent(in), optional :: dn          !! the overturning's change of N [N]

      n = dev%p_static*(1.0_dp + az/g)
      if (present(dn)) n = n + dn
   end function normal_force

   !> The bearing dev0 with p = max(N, 0) at the vertical acceleration az (and the overturning's
   !> dn, if given), as the laws take it; another device (no partner) as it is.
   elemental subroutine with_normal_force(dev0, az, dev, dn)
      type(device_type), intent(in) :: dev0         !! the device as the deck made it
      real(dp), intent(in) :: az                    !! vertical ground acceleration [m/s2]
      type(device_type), intent(inout) :: dev       !! its copy for the step, p set
      real(dp), intent(in), optional :: dn          !! the overturning's change of N [N]

      if (dev0%partner == 0) return
      dev%p = max(normal_force(dev0, az, dn), 0.0_dp)
   end subroutine with_normal_force

   !> Every device at the vertical acceleration az, as the laws and the techniques take them:
   !> a bearing's copy with p = max(N, 0) (with_normal_force), every other device's as it is.
   !> The one routine every technique calls for the normal forces at a time (explicit-shape
   !> arrays: no descriptor, no temporary, no allocation).
   pure subroutine devices_at_normal_force(nd, dev0, az, dev)
      integer, intent(in) :: nd                     !! devices
      type(device_type), intent(in) :: dev0(nd)     !! the devices as the deck made them
      real(dp), intent(in) :: az                    !! vertical ground acceleration [m/s2]
      type(device_type), intent(inout) :: dev(nd)   !! their copies for the time, p set
      integer :: d

      do d = 1, nd
         call with_normal_force(dev0(d), az, dev(d))
      end do
   end subroutine devices_at_normal_force

   !> Each device's smallest and largest normal force while the vertical acceleration spans
   !> [az_lo, az_hi] (N, not max(N, 0): N <= 0 is uplift): a bearing's N at both ends (N grows
   !> with az), another device's p for both.
   pure subroutine normal_force_range(nd, dev0, az_lo, az_hi, nrange)
      integer, intent(in) :: nd                     !! devices
      type(device_type), intent(in) :: dev0(nd)     !! the devices as the deck made them
      real(dp), intent(in) :: az_lo, az_hi          !! the vertical acceleration's extremes [m/s2]
      real(dp), intent(out) :: nrange(2, nd)        !! smallest and largest N [N]
      integer :: d

      do d = 1, nd
         nrange(:, d) = dev0(d)%p
         if (dev0(d)%partner == 0) cycle
         nrange(1, d) = normal_force(dev0(d), az_lo)
         nrange(2, d) = normal_force(dev0(d), az_hi)
      end do
   end subroutine normal_force_range

   !> The pendulum's stiffness beyond the one K holds, (P - P_static) / R, of a bearing whose
   !> normal force P varies (0 for a flat slider and for P = P_static) [N/m].
   elemental real(dp) function pendulum_excess(dev) result(kp)
      type(device_type), intent(in) :: dev          !! the bearing: p its current normal force

      kp = 0.0_dp
      if (dev%radius > 0.0_dp .and. dev%p /= dev%p_static) kp = (max(dev%p, 0.0_dp) - dev%p_static)/dev%radius
   end function pendulum_excess

end module fd_friction_planar
