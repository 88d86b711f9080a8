!> Unit tests of velocity-dependent friction of the velocity law (fd_friction_velocity):
!> mu(v) in the exponential form and as a table, and the force coefficients it gives in the
!> band and while sliding, and the sliding force at the step's end that the time-step loop
!> iterates (velocity_follow, friction_follow).
module test_fd_friction_mu
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_model, only: device_type, law_velocity, mu_constant, mu_exponential, mu_table, sliding_mu
   use fd_device_state, only: device_state, phase_stick, phase_slip_pos, phase_slip_neg
   use fd_friction_velocity, only: velocity_init, velocity_update, velocity_follow
   use fd_friction, only: follows_velocity, friction_follow
   use test_fd_helpers, only: check_close
   implicit none
   private

   public :: collect_friction_mu

contains

   subroutine collect_friction_mu(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("exponential mu(v)", test_exponential), &
                  new_unittest("table mu(v)", test_table), &
                  new_unittest("force coefficients with mu(v)", test_coefficients), &
                  new_unittest("sliding force at the step's end", test_follow) &
                  ]
   end subroutine collect_friction_mu

   subroutine test_exponential(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev

      dev = device_type(law=law_velocity, p=100.0_dp, mu=0.12_dp, eps=1.0e-3_dp)
      dev%mu_law = mu_exponential
      dev%mu_min = 0.05_dp
      dev%mu_rate = 20.0_dp
      call check_close(error, sliding_mu(dev, 0.0_dp), 0.05_dp, 1.0e-15_dp, 'mu(0) = mu_min')
      if (allocated(error)) return
      call check_close(error, sliding_mu(dev, -0.1_dp), 0.12_dp - 0.07_dp*exp(-2.0_dp), 1.0e-15_dp, &
                       'mu(-0.1) = mu_max - (mu_max - mu_min) exp(-rate |v|)')
      if (allocated(error)) return
      call check_close(error, sliding_mu(dev, 10.0_dp), 0.12_dp, 1.0e-15_dp, 'mu(large v) = mu_max')
      if (allocated(error)) return
      dev%mu_min = dev%mu
      call check(error, sliding_mu(dev, 0.3_dp) == dev%mu, 'mu_min = mu_max is the constant law')
   end subroutine test_exponential

   subroutine test_table(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev

      dev = device_type(law=law_velocity, p=100.0_dp, mu=0.1_dp)
      dev%mu_law = mu_table
      dev%n_mu_points = 3
      dev%mu_v(1:3) = [0.01_dp, 0.05_dp, 0.25_dp]
      dev%mu_at(1:3) = [0.04_dp, 0.08_dp, 0.1_dp]
      call check(error, sliding_mu(dev, 0.0_dp) == 0.04_dp .and. sliding_mu(dev, 0.01_dp) == 0.04_dp, &
                 'constant before the first point')
      if (allocated(error)) return
      call check_close(error, sliding_mu(dev, -0.03_dp), 0.06_dp, 1.0e-15_dp, 'linear between points')
      if (allocated(error)) return
      call check_close(error, sliding_mu(dev, 0.2_dp), 0.08_dp + 0.02_dp*0.75_dp, 1.0e-15_dp, 'second segment')
      if (allocated(error)) return
      call check(error, sliding_mu(dev, 3.0_dp) == 0.1_dp, 'constant after the last point')
   end subroutine test_table

   !> In the band the coupling is P mu(eps) / eps (continuous with the sliding force at
   !> |v| = eps); sliding, the force is P mu(|v|) at the velocity the step starts from.
   subroutine test_coefficients(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev
      type(device_state) :: st
      logical :: changed

      dev = device_type(law=law_velocity, p=100.0_dp, mu=0.12_dp, eps=1.0e-3_dp)
      dev%mu_law = mu_exponential
      dev%mu_min = 0.05_dp
      dev%mu_rate = 20.0_dp
      call velocity_init(dev, 0.0_dp, 0.0_dp, st)
      call check(error, st%phase == phase_stick, 'starts stuck')
      if (allocated(error)) return
      call check_close(error, st%cs*dev%eps, 100.0_dp*sliding_mu(dev, dev%eps), 1.0e-14_dp, &
                       'band coupling P mu(eps) / eps')
      if (allocated(error)) return
      call velocity_update(dev, 0.0_dp, 0.2_dp, st, changed)
      call check(error, changed .and. st%phase == phase_slip_pos, 'slides at v > eps')
      if (allocated(error)) return
      call check_close(error, st%f0, 100.0_dp*(0.12_dp - 0.07_dp*exp(-4.0_dp)), 1.0e-14_dp, 'sliding force P mu(v)')
      if (allocated(error)) return
      call velocity_update(dev, 0.0_dp, -0.05_dp, st, changed)
      call check(error, st%phase == phase_slip_neg, 'slides backwards')
      if (allocated(error)) return
      call check_close(error, st%f0, -100.0_dp*(0.12_dp - 0.07_dp*exp(-1.0_dp)), 1.0e-14_dp, &
                       'sliding force -P mu(|v|)')
      if (allocated(error)) return
      ! the same device with a constant mu (a device's law is fixed for a run: a new state)
      dev%mu_law = mu_constant
      call velocity_init(dev, 0.0_dp, 0.0_dp, st)
      call velocity_update(dev, 0.0_dp, -0.05_dp, st, changed)
      call check(error, changed .and. st%f0 == -100.0_dp*0.12_dp, 'constant law: P mu')
   end subroutine test_coefficients

   !> velocity_follow gives P mu(|v|) in the phase's direction to a sliding device with mu(v),
   !> and leaves f0 alone in the band or with a constant mu; friction_follow's change df, iterated
   !> on a block's trapezoidal step (v1 = v0 + h a0 / 2 - h f0 / (2 m)) on a linear table segment
   !> mu = c + d v, reaches the closed-form fixed point
   !> v1 = (v0 + h a0 / 2 - h P c / (2 m)) / (1 + h P d / (2 m)).
   subroutine test_follow(error)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev(1)
      type(device_state) :: st(1)
      real(dp), parameter :: m = 50.0_dp, h = 1.0e-3_dp, v0 = 0.3_dp, a0 = -2.0_dp
      real(dp) :: c, d, v1(1), df(1), exact
      integer :: it

      dev(1) = device_type(law=law_velocity, p=400.0_dp, mu=0.1_dp, eps=1.0e-3_dp)
      dev(1)%mu_law = mu_table
      dev(1)%n_mu_points = 2
      dev(1)%mu_v(1:2) = [0.1_dp, 0.5_dp]
      dev(1)%mu_at(1:2) = [0.05_dp, 0.15_dp]
      call check(error, all(follows_velocity(dev)), 'a table mu follows the velocity')
      if (allocated(error)) return
      st(1) = device_state(phase=phase_slip_neg, f0=-1.0_dp)
      call check_close(error, velocity_follow(dev(1), -0.3_dp, st(1)), -400.0_dp*0.1_dp, 1.0e-14_dp, &
                       'sliding backwards: -P mu(|v|)')
      if (allocated(error)) return
      st(1) = device_state(phase=phase_stick, cs=5.0_dp)
      call check(error, velocity_follow(dev(1), 0.3_dp, st(1)) == 0.0_dp, 'in the band: f0 as it is')
      if (allocated(error)) return
      ! the fixed point of a block's step, from the force at the step's start
      d = (0.15_dp - 0.05_dp)/0.4_dp
      c = 0.05_dp - d*0.1_dp
      st(1) = device_state(phase=phase_slip_pos, f0=400.0_dp*sliding_mu(dev(1), v0))
      do it = 1, 60
         v1 = v0 + 0.5_dp*h*a0 - 0.5_dp*h*st(1)%f0/m
         call friction_follow(1, [1], dev, v1, st, df)
         if (abs(df(1)) < 1.0e-13_dp) exit
         st(1)%f0 = st(1)%f0 + df(1)
      end do
      exact = (v0 + 0.5_dp*h*a0 - 0.5_dp*h*400.0_dp*c/m)/(1.0_dp + 0.5_dp*h*400.0_dp*d/m)
      call check_close(error, v1(1), exact, 1.0e-14_dp, 'the fixed point of the trapezoidal step')
      if (allocated(error)) return
      call check_close(error, st(1)%f0, 400.0_dp*(c + d*exact), 1.0e-12_dp, 'its force P mu(v1)')
      if (allocated(error)) return
      dev(1)%mu_law = mu_constant
      call check(error, .not. any(follows_velocity(dev)), 'a constant mu does not follow')
      if (allocated(error)) return
      st(1) = device_state(phase=phase_slip_pos, f0=40.0_dp)
      call check(error, velocity_follow(dev(1), 0.3_dp, st(1)) == 40.0_dp, 'constant mu: f0 as it is')
   end subroutine test_follow

end module test_fd_friction_mu
