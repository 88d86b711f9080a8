!> Unit tests of what each friction law says of itself (fd_friction's law properties): the
!> traits of the velocity, hysteretic and Coulomb laws as docs/theory.md states them (how a
!> sticking device joins the stuck system, its band and coupling variables, the checks that
!> apply, the energy it stores), and the per-device values each law gives (sticking spring
!> and dashpot, holding when stuck, capacity, band, stored energy). A law id without a case
!> has no traits and holds nothing.
!>
!> The values are exact in binary (P = 16 N, mu = 0.25, f = 2**-10 m, eps = 2**-7 m/s,
!> eps1 = 2**-6 m/s), so each is compared exactly.
module test_fd_friction_laws
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_model, only: device_type, law_velocity, law_hysteretic, law_coulomb, mu_table
   use fd_names, only: laws
   use fd_device_state, only: device_state, phase_stick, phase_slip_pos
   use fd_friction, only: law_traits_type, law_traits, law_stuck, stuck_none, stuck_rigid, stuck_spring, &
                          stuck_dashpot, law_band_name, law_coupling_name, law_checks_band_alternation, &
                          law_mu_of_speed, sticking_stiffness, sticking_damping, holds_when_stuck, &
                          links_when_stuck, friction_capacity, law_band, friction_energy, follows_velocity
   implicit none
   private

   public :: collect_friction_laws

   real(dp), parameter :: p = 16.0_dp             !! normal force [N]
   real(dp), parameter :: mu = 0.25_dp            !! P mu = 4 N
   real(dp), parameter :: f = 2.0_dp**(-10)       !! hysteretic sticking displacement [m]
   real(dp), parameter :: eps = 2.0_dp**(-7)      !! velocity band [m/s]
   real(dp), parameter :: eps1 = 2.0_dp**(-6)     !! hysteretic band [m/s]

contains

   subroutine collect_friction_laws(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("velocity law: traits", test_velocity_traits), &
                  new_unittest("hysteretic law: traits", test_hysteretic_traits), &
                  new_unittest("coulomb law: traits", test_coulomb_traits), &
                  new_unittest("a law id without a case", test_unknown_law), &
                  new_unittest("velocity device: dashpot, band, capacity", test_velocity_device), &
                  new_unittest("hysteretic device: spring, band, energy", test_hysteretic_device), &
                  new_unittest("coulomb device: rigid link", test_coulomb_device), &
                  new_unittest("no capacity: no device holds", test_no_capacity), &
                  new_unittest("velocity device: mu(v) sets hold and capacity", test_velocity_mu_table) &
                  ]
   end subroutine collect_friction_laws

   pure function device(law) result(dev)
      integer, intent(in) :: law
      type(device_type) :: dev
      dev = device_type(node_i=1, node_j=0, law=law, p=p, mu=mu, eps=eps, eps1=eps1, f=f)
   end function device

   subroutine test_velocity_traits(error)
      type(error_type), allocatable, intent(out) :: error
      type(law_traits_type) :: t

      t = law_traits(law_velocity)
      call check(error, t%stuck == stuck_dashpot .and. law_stuck(law_velocity) == stuck_dashpot, &
                 'a sticking velocity device is a dashpot (eq. 6)')
      if (allocated(error)) return
      call check(error, law_band_name(law_velocity) == 'eps' .and. law_coupling_name(law_velocity) == 'eps', &
                 'band and coupling set by eps')
      if (allocated(error)) return
      call check(error, t%checks_correctness .and. t%checks_band_alternation .and. &
                 law_checks_band_alternation(law_velocity) .and. .not. t%checks_stick_ringing, &
                 'eq. 9 and band alternation, no ringing')
      if (allocated(error)) return
      call check(error, .not. t%stores_energy .and. law_mu_of_speed(law_velocity), &
                 'no stored energy; mu may depend on the speed')
   end subroutine test_velocity_traits

   subroutine test_hysteretic_traits(error)
      type(error_type), allocatable, intent(out) :: error
      type(law_traits_type) :: t

      t = law_traits(law_hysteretic)

      call check(error, law_stuck(law_hysteretic) == stuck_spring, 'a sticking hysteretic device is a spring (eq. 3)')
      if (allocated(error)) return
      call check(error, law_band_name(law_hysteretic) == 'eps1' .and. law_coupling_name(law_hysteretic) == 'f', &
                 'band eps1, spring set by f')
      if (allocated(error)) return
      call check(error, t%checks_correctness .and. t%checks_stick_ringing .and. &
                 .not. law_checks_band_alternation(law_hysteretic), 'eq. 12 and stick ringing, no band alternation')
      if (allocated(error)) return
      call check(error, t%stores_energy .and. .not. law_mu_of_speed(law_hysteretic), &
                 'its spring stores energy; constant mu')
   end subroutine test_hysteretic_traits

   subroutine test_coulomb_traits(error)
      type(error_type), allocatable, intent(out) :: error
      type(law_traits_type) :: t

      t = law_traits(law_coulomb)

      call check(error, law_stuck(law_coulomb) == stuck_rigid, 'a sticking Coulomb device is a rigid link')
      if (allocated(error)) return
      call check(error, law_band_name(law_coulomb) == '' .and. law_coupling_name(law_coulomb) == '', &
                 'no band, no coupling variable')
      if (allocated(error)) return
      call check(error, .not. (t%checks_correctness .or. t%checks_stick_ringing .or. &
                               law_checks_band_alternation(law_coulomb) .or. t%stores_energy .or. &
                               law_mu_of_speed(law_coulomb)), 'no check, no energy, constant mu')
   end subroutine test_coulomb_traits

   subroutine test_unknown_law(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev
      type(law_traits_type) :: t
      integer :: law

      do law = 0, size(laws) + 1, size(laws) + 1
         t = law_traits(law)
         call check(error, law_stuck(law) == stuck_none .and. law_band_name(law) == '' .and. &
                    .not. t%checks_correctness .and. .not. t%stores_energy, 'no traits')
         if (allocated(error)) return
         dev = device(law)
         call check(error, .not. holds_when_stuck(dev) .and. .not. links_when_stuck(dev) .and. &
                    sticking_stiffness(dev) == 0.0_dp .and. sticking_damping(dev) == 0.0_dp .and. &
                    law_band(dev) == 0.0_dp, 'holds nothing, no spring, no dashpot, no band')
         if (allocated(error)) return
      end do
   end subroutine test_unknown_law

   subroutine test_velocity_device(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev

      dev = device(law_velocity)
      call check(error, sticking_damping(dev) == p*mu/eps .and. sticking_stiffness(dev) == 0.0_dp, &
                 'dashpot P mu / eps = 512 N s/m, no spring')
      if (allocated(error)) return
      call check(error, holds_when_stuck(dev) .and. links_when_stuck(dev), 'holds as a rigid link of the stuck system')
      if (allocated(error)) return
      call check(error, friction_capacity(dev) == 4.0_dp .and. law_band(dev) == eps, 'capacity P mu, band eps')
      if (allocated(error)) return
      call check(error, friction_energy(dev, device_state(phase=phase_stick, cs=p*mu/eps), 1.0_dp) == 0.0_dp, &
                 'stores no energy')
      if (allocated(error)) return
      call check(error, .not. follows_velocity(dev), 'a constant mu is not followed within a step')
   end subroutine test_velocity_device

   subroutine test_hysteretic_device(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev
      type(device_state) :: st
      real(dp) :: k

      dev = device(law_hysteretic)
      k = p*mu/f
      call check(error, sticking_stiffness(dev) == k .and. sticking_damping(dev) == 0.0_dp, &
                 'spring P mu / f = 4096 N/m, no dashpot')
      if (allocated(error)) return
      call check(error, holds_when_stuck(dev) .and. .not. links_when_stuck(dev), &
                 'holds through its spring, not as a rigid link')
      if (allocated(error)) return
      call check(error, friction_capacity(dev) == 4.0_dp .and. law_band(dev) == eps1, 'capacity P mu, band eps1')
      if (allocated(error)) return
      ! sticking at s = f / 2 about the centre 0: F = k s = 2 N, energy F**2 / (2 k)
      st = device_state(phase=phase_stick, ks=k, f0=0.0_dp)
      call check(error, friction_energy(dev, st, f/2.0_dp) == 2.0_dp**2/(2.0_dp*k), 'sticking: F**2 / (2 k)')
      if (allocated(error)) return
      ! sliding the spring holds P mu
      st = device_state(phase=phase_slip_pos, ks=0.0_dp, f0=4.0_dp)
      call check(error, friction_energy(dev, st, 3.0_dp) == 4.0_dp**2/(2.0_dp*k), 'sliding: (P mu)**2 / (2 k)')
   end subroutine test_hysteretic_device

   subroutine test_coulomb_device(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev

      dev = device(law_coulomb)
      call check(error, sticking_stiffness(dev) == 0.0_dp .and. sticking_damping(dev) == 0.0_dp, &
                 'no spring, no dashpot')
      if (allocated(error)) return
      call check(error, holds_when_stuck(dev) .and. links_when_stuck(dev), 'a rigid link')
      if (allocated(error)) return
      call check(error, friction_capacity(dev) == 4.0_dp .and. law_band(dev) == 0.0_dp, 'capacity P mu, no band')
      if (allocated(error)) return
      call check(error, friction_energy(dev, device_state(f0=4.0_dp), 1.0_dp) == 0.0_dp, 'stores no energy')
   end subroutine test_coulomb_device

   subroutine test_no_capacity(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev(3)

      dev = [device(law_velocity), device(law_hysteretic), device(law_coulomb)]
      dev%mu = 0.0_dp
      call check(error, .not. any(holds_when_stuck(dev)) .and. .not. any(links_when_stuck(dev)), 'none holds')
      if (allocated(error)) return
      call check(error, all(sticking_stiffness(dev) == 0.0_dp) .and. all(friction_capacity(dev) == 0.0_dp), &
                 'no spring, no capacity')
   end subroutine test_no_capacity

   !> mu(v) from a table that is 0 up to past eps and 0.5 beyond: the device holds nothing
   !> while stuck (its band's coupling is 0) but can slide with P * 0.5; it is followed.
   subroutine test_velocity_mu_table(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev

      dev = device(law_velocity)
      dev%mu_law = mu_table
      dev%n_mu_points = 3
      dev%mu_v(1:3) = [0.0_dp, 2.0_dp*eps, 4.0_dp*eps]
      dev%mu_at(1:3) = [0.0_dp, 0.0_dp, 0.5_dp]
      dev%mu = 0.5_dp
      call check(error, .not. holds_when_stuck(dev) .and. sticking_damping(dev) == 0.0_dp, &
                 'mu(eps) = 0: no dashpot, holds nothing')
      if (allocated(error)) return
      call check(error, friction_capacity(dev) == 8.0_dp, 'capacity P max mu = 8 N')
      if (allocated(error)) return
      call check(error, follows_velocity(dev), 'a speed-dependent mu is followed within a step')
   end subroutine test_velocity_mu_table

end module test_fd_friction_laws
