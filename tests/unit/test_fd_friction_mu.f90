!> Unit tests of velocity-dependent friction of the velocity law (fd_friction_velocity):
!> mu(v) in the exponential form and as a table, and the force coefficients it gives in the
!> band and while sliding.
module test_fd_friction_mu
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_model, only: device_type, law_velocity, mu_constant, mu_exponential, mu_table
   use fd_device_state, only: device_state, phase_stick, phase_slip_pos, phase_slip_neg
   use fd_friction_velocity, only: sliding_mu, velocity_init, velocity_update
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
                  new_unittest("force coefficients with mu(v)", test_coefficients) &
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

end module test_fd_friction_mu
