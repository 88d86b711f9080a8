!> Unit tests of the planar bearings' laws (fd_friction_planar): each law for motion along one
!> axis gives the one-dimensional law's state to the bit; off the axes the velocity law's disc
!> and sliding force P mu v/|v|, its correctness condition on the resultant, and the
!> hysteretic law's circular yield surface, radial return and end of sliding; a normal force
!> that varies (p the current N, p_static the pendulum's in K) and uplift; the overturning's
!> share of it (fd_overturning: a rigid mat's arms, dN of the floors' inertia forces).
!>
!> P = 16 N, mu = 0.25 (P mu = 4 N), f = 2**-10 m, eps = 2**-7 m/s, eps1 = 2**-6 m/s.
module test_fd_friction_planar
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_model, only: device_type, law_velocity, law_hysteretic, model_type
   use fd_overturning, only: overturning_arms, overturning_forces
   use test_fd_helpers, only: check_close
   use fd_device_state, only: device_state, phase_stick, phase_slip_pos, phase_slip_neg
   use fd_friction_velocity, only: velocity_update, velocity_init
   use fd_friction_hysteretic, only: hysteretic_update, hysteretic_init
   use fd_friction_planar, only: planar_velocity_update, planar_velocity_init, planar_velocity_correct, &
                                 planar_hysteretic_update, planar_hysteretic_init, planar_hysteretic_correct, &
                                 pendulum_excess, normal_force, with_normal_force, devices_at_normal_force, &
                                 normal_force_range
   implicit none
   private

   public :: collect_friction_planar

   real(dp), parameter :: p = 16.0_dp, mu = 0.25_dp, f = 2.0_dp**(-10)
   real(dp), parameter :: eps = 2.0_dp**(-7), eps1 = 2.0_dp**(-6)

contains

   subroutine collect_friction_planar(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("velocity: along x, the 1D law's states", test_velocity_axis), &
                  new_unittest("velocity: the disc and the force P mu v/|v|", test_velocity_disc), &
                  new_unittest("velocity: correctness on the resultant", test_velocity_correct), &
                  new_unittest("hysteretic: along y, the 1D law's states", test_hysteretic_axis), &
                  new_unittest("hysteretic: circular yield surface", test_hysteretic_yield), &
                  new_unittest("hysteretic: radial return while sliding", test_hysteretic_return), &
                  new_unittest("hysteretic: end of sliding, force continuous", test_hysteretic_end), &
                  new_unittest("hysteretic: a fast turn unloads elastically", test_hysteretic_turn), &
                  new_unittest("a varying normal force: friction of N, the pendulum's excess", test_normal_force), &
                  new_unittest("uplift (N <= 0): no force, a hysteretic spring unloaded", test_uplift), &
                  new_unittest("overturning: a rigid mat's arms, 2x2 and on a line", test_overturning_arms), &
                  new_unittest("overturning: dN of a block at height h on two rows", test_overturning_forces), &
                  new_unittest("every device at a vertical acceleration; N's range", test_devices_normal_force) &
                  ]
   end subroutine collect_friction_planar

   pure function device(law) result(dev)
      integer, intent(in) :: law
      type(device_type) :: dev
      dev = device_type(law=law, p=p, mu=mu, eps=eps, eps1=eps1, f=f)
   end function device

   !> Whether two states are the same to the bit (phase, coefficients, centre).
   pure logical function same(a, b)
      type(device_state), intent(in) :: a, b
      same = a%phase == b%phase .and. a%ks == b%ks .and. a%cs == b%cs .and. a%f0 == b%f0 .and. &
             a%centre == b%centre .and. (a%armed .eqv. b%armed)
   end function same

   subroutine test_velocity_axis(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st1, pair(2)
      logical :: ch1, ch(2)
      real(dp), parameter :: v(6) = [0.0_dp, 3.0e-3_dp, 0.05_dp, -0.2_dp, -1.0e-3_dp, 0.7_dp]
      real(dp) :: s
      integer :: k

      call velocity_init(device(law_velocity), 0.0_dp, 0.0_dp, st1)
      call planar_velocity_init(device(law_velocity), [0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], pair)
      do k = 1, size(v)
         s = 0.01_dp*k
         call velocity_update(device(law_velocity), s, v(k), st1, ch1)
         call planar_velocity_update(device(law_velocity), [s, 0.0_dp], [v(k), 0.0_dp], pair, ch)
         call check(error, same(pair(1), st1) .and. (ch(1) .eqv. ch1), "along x: the 1D law's state")
         if (allocated(error)) return
         call check(error, pair(2)%f0 == 0.0_dp .and. pair(2)%ks == 0.0_dp, "along x: no force along y")
         if (allocated(error)) return
      end do
   end subroutine test_velocity_axis

   subroutine test_velocity_disc(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: pair(2)
      logical :: ch(2)

      call planar_velocity_init(device(law_velocity), [0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], pair)
      ! each component inside the band, the resultant outside the disc: sliding along (1, 1)
      call planar_velocity_update(device(law_velocity), [0.0_dp, 0.0_dp], [0.75_dp*eps, 0.75_dp*eps], pair, ch)
      call check(error, pair(1)%phase == phase_slip_pos .and. pair(2)%phase == phase_slip_pos .and. all(ch), &
                 "|v| = 1.06 eps slides")
      if (allocated(error)) return
      call check(error, abs(pair(1)%f0 - p*mu/sqrt(2.0_dp)) < 1.0e-15_dp*p*mu .and. pair(1)%f0 == pair(2)%f0 .and. &
                 pair(1)%cs == 0.0_dp, "the force P mu v/|v|")
      if (allocated(error)) return
      ! along (3, -4): F = P mu (0.6, -0.8)
      call planar_velocity_update(device(law_velocity), [0.0_dp, 0.0_dp], [0.3_dp, -0.4_dp], pair, ch)
      call check(error, abs(pair(1)%f0 - 0.6_dp*p*mu) < 1.0e-15_dp .and. abs(pair(2)%f0 + 0.8_dp*p*mu) < 1.0e-15_dp &
                 .and. pair(2)%phase == phase_slip_neg .and. ch(2) .and. .not. ch(1), "F = P mu (0.6, -0.8)")
      if (allocated(error)) return
      ! inside the disc: each component its dashpot P mu / eps
      call planar_velocity_update(device(law_velocity), [0.0_dp, 0.0_dp], [0.6_dp*eps, 0.7_dp*eps], pair, ch)
      call check(error, all(pair%phase == phase_stick) .and. all(pair%cs == p*mu/eps) .and. all(pair%f0 == 0.0_dp), &
                 "|v| = 0.92 eps sticks, dashpots P mu / eps")
   end subroutine test_velocity_disc

   subroutine test_velocity_correct(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: pair(2)
      real(dp), parameter :: n = 2.0_dp
      real(dp) :: a

      pair%phase = phase_slip_pos
      a = 2.0_dp*eps
      ! a quarter turn within a step: v.v_old = 0 violates; each component alone would not see it
      call check(error, .not. planar_velocity_correct(device(law_velocity), n, pair, [a, 0.0_dp], [0.0_dp, a]), &
                 "a quarter turn violates")
      if (allocated(error)) return
      call check(error, planar_velocity_correct(device(law_velocity), n, pair, [a, a], [a, 0.9_dp*a]), &
                 "a small turn is correct")
      if (allocated(error)) return
      ! the bound eps^2 (1 - 1/n) on the dot product: v.v_old = 0.5 eps^2 is not above it
      call check(error, .not. planar_velocity_correct(device(law_velocity), n, pair, [0.5_dp*eps, 0.5_dp*eps], &
                                                      [eps, 0.0_dp]), "v.v_old = eps^2 / 2 is not > eps^2 (1 - 1/2)")
      if (allocated(error)) return
      pair%phase = phase_stick
      call check(error, planar_velocity_correct(device(law_velocity), n, pair, [a, 0.0_dp], [-a, 0.0_dp]), &
                 "not checked while sticking")
   end subroutine test_velocity_correct

   subroutine test_hysteretic_axis(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: st1, pair(2)
      logical :: ch1, ch(2)
      real(dp), parameter :: s(7) = [0.5_dp, 1.5_dp, 3.0_dp, 4.0_dp, 4.0_dp, 2.0_dp, -1.0_dp]*f
      real(dp), parameter :: v(7) = [0.1_dp, 1.0_dp, 2.0_dp, 0.5_dp, -0.1_dp, -1.0_dp, -2.0_dp]*eps1
      integer :: k

      call hysteretic_init(device(law_hysteretic), 0.0_dp, 0.0_dp, st1)
      call planar_hysteretic_init(device(law_hysteretic), [0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], pair)
      do k = 1, size(s)
         call hysteretic_update(device(law_hysteretic), s(k), v(k), st1, ch1)
         call planar_hysteretic_update(device(law_hysteretic), [0.0_dp, s(k)], [0.0_dp, v(k)], pair, ch)
         call check(error, same(pair(2), st1) .and. (ch(2) .eqv. ch1), "along y: the 1D law's state")
         if (allocated(error)) return
      end do
   end subroutine test_hysteretic_axis

   subroutine test_hysteretic_yield(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: pair(2)
      logical :: ch(2)
      real(dp) :: k

      k = p*mu/f
      call planar_hysteretic_init(device(law_hysteretic), [0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], pair)
      ! |k s| = 0.8 sqrt(2) P mu < P mu? no: 1.13 P mu, on the circle's outside: slides along (1, 1)
      call planar_hysteretic_update(device(law_hysteretic), [0.8_dp*f, 0.8_dp*f], [eps1, eps1], pair, ch)
      call check(error, all(pair%phase == phase_slip_pos) .and. all(ch) .and. pair(1)%armed, "slides along (1, 1)")
      if (allocated(error)) return
      call check(error, abs(pair(1)%f0 - p*mu/sqrt(2.0_dp)) < 1.0e-14_dp .and. &
                 abs(k*(0.8_dp*f - pair(1)%centre) - pair(1)%f0) < 1.0e-12_dp, "radial return onto the circle")
      if (allocated(error)) return
      ! inside the circle: |k s| = 0.6 sqrt(2) P mu = 0.85 P mu sticks (each component 0.6 P mu)
      call planar_hysteretic_init(device(law_hysteretic), [0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], pair)
      call planar_hysteretic_update(device(law_hysteretic), [0.6_dp*f, -0.6_dp*f], [eps1, -eps1], pair, ch)
      call check(error, all(pair%phase == phase_stick) .and. .not. any(ch) .and. all(pair%ks == k), &
                 "inside the circle: sticks, springs P mu / f")
   end subroutine test_hysteretic_yield

   subroutine test_hysteretic_return(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: pair(2)
      logical :: ch(2)

      ! sliding along x from the start, centre at s - f
      call planar_hysteretic_init(device(law_hysteretic), [0.0_dp, 0.0_dp], [2.0_dp*eps1, 0.0_dp], pair)
      call check(error, pair(1)%phase == phase_slip_pos .and. pair(1)%f0 == p*mu .and. pair(1)%centre == -f, &
                 "starts sliding along x")
      if (allocated(error)) return
      ! then moved by (0, f): the trial force P mu (1, 1), returned to P mu (1, 1)/sqrt(2)
      call planar_hysteretic_update(device(law_hysteretic), [0.0_dp, f], [0.0_dp, 2.0_dp*eps1], pair, ch)
      call check(error, abs(pair(1)%dir - 1.0_dp/sqrt(2.0_dp)) < 1.0e-15_dp .and. &
                 abs(pair(2)%dir - 1.0_dp/sqrt(2.0_dp)) < 1.0e-15_dp .and. pair(1)%phase == phase_slip_pos, &
                 "the direction of the trial force")
      if (allocated(error)) return
      call check(error, abs(hypot(pair(1)%f0, pair(2)%f0) - p*mu) < 1.0e-14_dp, "|F| = P mu")
   end subroutine test_hysteretic_return

   subroutine test_hysteretic_end(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: pair(2)
      logical :: ch(2)
      real(dp) :: k, fx, fy
      real(dp), parameter :: s(2) = [3.0_dp*f, 4.0_dp*f]

      k = p*mu/f
      call planar_hysteretic_init(device(law_hysteretic), [0.0_dp, 0.0_dp], [0.6_dp*eps1*2, 0.8_dp*eps1*2], pair)
      ! armed; the velocity turned against the sliding direction inside the disc: sticks
      call planar_hysteretic_update(device(law_hysteretic), s, [-0.1_dp*eps1, 0.05_dp*eps1], pair, ch)
      call check(error, all(pair%phase == phase_stick) .and. all(ch), "sticks at the turn inside the disc")
      if (allocated(error)) return
      fx = k*(s(1) - pair(1)%centre)
      fy = k*(s(2) - pair(2)%centre)
      call check(error, abs(fx - 0.6_dp*p*mu) < 1.0e-12_dp .and. abs(fy - 0.8_dp*p*mu) < 1.0e-12_dp, &
                 "the force P mu d stays at the end of sliding")
      if (allocated(error)) return
      call check(error, planar_hysteretic_correct(device(law_hysteretic), 2.0_dp, pair, [1.0_dp, 0.0_dp], &
                                                  [-1.0_dp, 0.0_dp]), "not checked while sticking")
   end subroutine test_hysteretic_end

   subroutine test_hysteretic_turn(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_state) :: pair(2)
      logical :: ch(2)
      real(dp) :: k
      real(dp), parameter :: s(2) = [3.0_dp*f, 4.0_dp*f]

      k = p*mu/f
      ! armed along (0.6, 0.8); the velocity turned beyond 90 degrees from the force at a speed
      ! far outside the disc, not along the slide's line: the radial return's elastic
      ! unloading (the trial force falls inside the circle), not a slide along v
      call planar_hysteretic_init(device(law_hysteretic), [0.0_dp, 0.0_dp], [0.6_dp*eps1*2, 0.8_dp*eps1*2], pair)
      call planar_hysteretic_update(device(law_hysteretic), s, [-8.0_dp*eps1, 2.0_dp*eps1], pair, ch)
      call check(error, all(pair%phase == phase_stick) .and. all(ch), "sticks after a fast turn")
      if (allocated(error)) return
      call check(error, abs(k*(s(1) - pair(1)%centre) - 0.6_dp*p*mu) < 1.0e-12_dp .and. &
                 abs(k*(s(2) - pair(2)%centre) - 0.8_dp*p*mu) < 1.0e-12_dp, "the force P mu d continuous")
      if (allocated(error)) return
      ! a reversal along the slide's line is the 1D law's: slides along v
      call planar_hysteretic_init(device(law_hysteretic), [0.0_dp, 0.0_dp], [0.6_dp*eps1*2, 0.8_dp*eps1*2], pair)
      call planar_hysteretic_update(device(law_hysteretic), s, [-0.6_dp*eps1*4, -0.8_dp*eps1*4], pair, ch)
      call check(error, pair(1)%phase == phase_slip_neg .and. pair(2)%phase == phase_slip_neg, &
                 "a reversal along the line slides along v")
   end subroutine test_hysteretic_turn

   !> A bearing of P = 16 N (p_static) on a pendulum of R = 2 m now at N = 8 N: the friction is
   !> N mu (sliding force, band dashpot, sticking spring), and f0 holds (N - P) / R s.
   subroutine test_normal_force(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev, lifted
      type(device_state) :: pair(2)
      logical :: ch(2)
      real(dp), parameter :: s(2) = [0.5_dp, -0.25_dp], n = 8.0_dp, r = 2.0_dp
      real(dp) :: kp

      dev = device(law_velocity)
      dev%radius = r
      dev%p_static = p
      call check(error, pendulum_excess(dev), 0.0_dp)   ! N = P: no excess
      if (allocated(error)) return
      ! N = P (1 + az / g): P at az = 0, 0 at az = -g, 1.5 P at g / 2 (upward); the laws get max(N, 0)
      call check(error, normal_force(dev, 0.0_dp) == p .and. normal_force(dev, -9.80665_dp) == 0.0_dp .and. &
                 normal_force(dev, 0.5_dp*9.80665_dp) == 1.5_dp*p, "N = P (1 + az / g)")
      if (allocated(error)) return
      dev%partner = 2
      lifted = dev
      call with_normal_force(dev, -2.0_dp*9.80665_dp, lifted)
      call check(error, lifted%p == 0.0_dp .and. lifted%p_static == p, "lifted: p = 0, p_static kept")
      if (allocated(error)) return
      dev%p = n
      kp = pendulum_excess(dev)
      call check(error, kp, (n - p)/r)
      if (allocated(error)) return
      ! sliding along x: f0 = N mu + kp s
      call planar_velocity_init(dev, s, [2.0_dp*eps, 0.0_dp], pair)
      call check(error, pair(1)%f0 == n*mu + kp*s(1) .and. pair(2)%f0 == kp*s(2), "sliding: N mu d + kp s")
      if (allocated(error)) return
      ! in the disc: the dashpot N mu / eps
      call planar_velocity_update(dev, s, [0.0_dp, 0.0_dp], pair, ch)
      call check(error, all(pair%phase == phase_stick) .and. all(pair%cs == n*mu/eps) .and. &
                 pair(1)%f0 == kp*s(1), "in the disc: N mu / eps")
      if (allocated(error)) return
      ! hysteretic: sticking spring N mu / f, kept up while sticking as N changes
      dev%law = law_hysteretic
      call planar_hysteretic_init(dev, [0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], pair)
      dev%p = 2.0_dp*n
      call planar_hysteretic_update(dev, [0.5_dp*f, 0.0_dp], [0.0_dp, 0.0_dp], pair, ch)
      call check(error, all(pair%phase == phase_stick) .and. all(pair%ks == 2.0_dp*n*mu/f) .and. &
                 pair(1)%f0 == 0.0_dp, "sticking: the spring of the current N")
      if (allocated(error)) return
      ! its yield is |s - c| >= f whatever N: 1.01 f slides at N mu
      call planar_hysteretic_update(dev, [1.01_dp*f, 0.0_dp], [eps1, 0.0_dp], pair, ch)
      call check(error, pair(1)%phase == phase_slip_pos .and. pair(1)%f0 == 2.0_dp*n*mu, "slides at N mu")
   end subroutine test_normal_force

   !> devices_at_normal_force: a bearing's components take p = max(N, 0), a 1D device (no
   !> partner) keeps its p; normal_force_range: a bearing's N at the extremes of az (N < 0 kept:
   !> uplift), a 1D device's p twice.
   subroutine test_devices_normal_force(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev0(3), dev(3)
      real(dp) :: nr(2, 3)
      real(dp), parameter :: g = 9.80665_dp

      dev0 = device(law_velocity)
      dev0%p_static = p
      dev0(1)%partner = 2
      dev0(2)%partner = 1
      dev = dev0
      call devices_at_normal_force(3, dev0, 0.5_dp*g, dev)
      call check(error, dev(1)%p == 1.5_dp*p .and. dev(2)%p == 1.5_dp*p .and. dev(3)%p == p, "N at g / 2 up")
      if (allocated(error)) return
      call devices_at_normal_force(3, dev0, -2.0_dp*g, dev)
      call check(error, dev(1)%p == 0.0_dp .and. dev(2)%p == 0.0_dp .and. dev(3)%p == p, "lifted: p = 0")
      if (allocated(error)) return
      call normal_force_range(3, dev0, -2.0_dp*g, 0.5_dp*g, nr)
      call check(error, all(nr(:, 1) == [-p, 1.5_dp*p]) .and. all(nr(:, 2) == [-p, 1.5_dp*p]) .and. &
                 all(nr(:, 3) == p), "N's range: -P (uplift) to 1.5 P; a 1D device's p")
   end subroutine test_devices_normal_force

   !> N <= 0 (p = 0 given to the law): no friction, and a pendulum's excess -P / R s that
   !> cancels K's P / R s; a hysteretic bearing sliding when it lifts off comes down sticking
   !> with its spring unloaded (c = s).
   subroutine test_uplift(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev
      type(device_state) :: pair(2)
      logical :: ch(2)
      real(dp), parameter :: s(2) = [0.5_dp, -0.25_dp], r = 2.0_dp

      dev = device(law_velocity)
      dev%radius = r
      dev%p_static = p
      dev%p = 0.0_dp
      call planar_velocity_init(dev, s, [2.0_dp*eps, eps], pair)
      call check(error, all(pair%phase == phase_stick) .and. all(pair%cs == 0.0_dp) .and. &
                 all(pair%ks == 0.0_dp) .and. pair(1)%f0 == -p/r*s(1) .and. pair(2)%f0 == -p/r*s(2), &
                 "velocity law lifted: no friction, -P / R s")
      if (allocated(error)) return
      dev%law = law_hysteretic
      dev%radius = 0.0_dp
      dev%p = p
      call planar_hysteretic_init(dev, [0.0_dp, 0.0_dp], [2.0_dp*eps1, 0.0_dp], pair)
      call check(error, pair(1)%phase == phase_slip_pos, "slides")
      if (allocated(error)) return
      dev%p = 0.0_dp
      call planar_hysteretic_update(dev, s, [2.0_dp*eps1, 0.0_dp], pair, ch)
      call check(error, all(pair%phase == phase_stick) .and. all(ch) .and. all(pair%ks == 0.0_dp) .and. &
                 all(pair%f0 == 0.0_dp) .and. all(pair%centre == s), "hysteretic lifted: no force, c = s")
      if (allocated(error)) return
      dev%p = p
      call planar_hysteretic_update(dev, s, [0.0_dp, 0.0_dp], pair, ch)
      call check(error, all(pair%phase == phase_stick) .and. all(pair%ks == p*mu/f) .and. &
                 abs(pair(1)%ks*s(1) + pair(1)%f0) == 0.0_dp, "down again: sticks, unloaded")
   end subroutine test_uplift

   !> Four bearings at (+-3, +-2) m: S = diag(36, 16), arms (x'/36, y'/16). A skewed triangle
   !> (S not diagonal): sum of the arms 0 and sum arm r'' = I (S^-1 S), so dN = -arm . O sums to 0
   !> and balances any moment O. Bearings of a storey on one line, or one alone: that storey.
   subroutine test_overturning_arms(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: arm4(2, 4), arm3(2, 3), arm5(2, 5), id(2, 2), xr(3), yr(3)
      real(dp), parameter :: x3(3) = [-3.0_dp, 4.0_dp, 1.5_dp], y3(3) = [-2.0_dp, -1.0_dp, 3.5_dp]
      integer :: bad, b

      call overturning_arms([1, 1, 1, 1], [-3.0_dp, 3.0_dp, 3.0_dp, -3.0_dp], [-2.0_dp, -2.0_dp, 2.0_dp, 2.0_dp], &
                            arm4, bad)
      call check(error, bad == 0 .and. &
                 maxval(abs(arm4(1, :) - [-3.0_dp, 3.0_dp, 3.0_dp, -3.0_dp]/36.0_dp)) < 1.0e-16_dp .and. &
                 maxval(abs(arm4(2, :) - [-2.0_dp, -2.0_dp, 2.0_dp, 2.0_dp]/16.0_dp)) < 1.0e-16_dp, &
                 "four corners: x'/36, y'/16")
      if (allocated(error)) return
      call overturning_arms([2, 2, 2], x3, y3, arm3, bad)
      xr = x3 - sum(x3)/3.0_dp
      yr = y3 - sum(y3)/3.0_dp
      do b = 1, 2
         id(b, 1) = sum(arm3(b, :)*xr)
         id(b, 2) = sum(arm3(b, :)*yr)
      end do
      call check(error, bad == 0 .and. maxval(abs(sum(arm3, dim=2))) < 1.0e-15_dp, "skewed: the arms sum to 0")
      if (allocated(error)) return
      call check(error, maxval(abs(id - reshape([1.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [2, 2]))) < 1.0e-14_dp, &
                 "skewed: sum arm r'' = I")
      if (allocated(error)) return
      ! storey 1 fine, storey 3 on a line (y = 1), storey 1 first: storey 3 reported
      call overturning_arms([1, 3, 1, 3, 1], [0.0_dp, -1.0_dp, 4.0_dp, 2.0_dp, 0.0_dp], &
                            [0.0_dp, 1.0_dp, 0.0_dp, 1.0_dp, 3.0_dp], arm5, bad)
      call check(error, bad == 3, "a storey's bearings on one line")
      if (allocated(error)) return
      call overturning_arms([1], [2.0_dp], [1.0_dp], arm5(:, 1:1), bad)
      call check(error, bad == 1, "one bearing alone")
   end subroutine test_overturning_arms

   !> A base mat (floor 1, 2000 kg, in the bearing plane) and a block (floor 2, 1000 kg, 3 m above
   !> it) on four bearings at (+-3, +-2) m; the table at 2 m/s2 along x and 1 m/s2 along y (its
   !> second component), the block 0.5 m/s2 along x relative to it: O = 1000 3 (2.5, 1), and
   !> dN = -(O_x x'/36 + O_y y'/16); the mat carries no moment. With N = P + dN.
   subroutine test_overturning_forces(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(device_type) :: dev
      real(dp) :: dn(4), a(6)
      real(dp), parameter :: x4(4) = [-3.0_dp, 3.0_dp, 3.0_dp, -3.0_dp], y4(4) = [-2.0_dp, -2.0_dp, 2.0_dp, 2.0_dp]
      integer :: bad, b

      model%n_floors = 2
      model%n_dof = 6
      model%mass = [2000.0_dp, 2000.0_dp, 1.0e4_dp, 1000.0_dp, 1000.0_dp, 5.0e3_dp]
      model%floor_height = [0.0_dp, 3.0_dp]
      model%influence = [1.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, 0.0_dp]
      model%influence2 = [0.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp]
      model%overturning = .true.
      model%ot_storey = [1, 1, 1, 1]
      allocate (model%ot_arm(2, 4))
      call overturning_arms(model%ot_storey, x4, y4, model%ot_arm, bad)
      a = [7.0_dp, -3.0_dp, 0.2_dp, 0.5_dp, 0.0_dp, 0.1_dp]
      call overturning_forces(model, a, 2.0_dp, 1.0_dp, dn)
      do b = 1, 4
         call check_close(error, dn(b), -(3000.0_dp*2.5_dp*x4(b)/36.0_dp + 3000.0_dp*y4(b)/16.0_dp), 1.0e-15_dp, &
                          "dN of bearing b")
         if (allocated(error)) return
      end do
      call check(error, abs(sum(dn)) < 1.0e-12_dp, "sum dN = 0")
      if (allocated(error)) return
      dev = device(law_velocity)
      dev%p_static = p
      call check(error, normal_force(dev, 0.0_dp, dn(1)) == p + dn(1) .and. normal_force(dev, 0.0_dp) == p, &
                 "N = P (1 + az / g) + dN")
   end subroutine test_overturning_forces

end module test_fd_friction_planar
