!> Unit tests of Newmark's own frequency and damping of an oscillator (fd_stick_ringing's
!> newmark_frequency): the closed forms of the average and linear acceleration rules, the
!> small-step damping of gamma > 1/2, and the frequency of the recursion itself, run step
!> by step (an independent computation); a bearing's observed normal force beyond the deck's
!> moves its sticking spring, its frequency error and its capacities (ringing_normal_force);
!> the devices watched of a model of node pairs are the same through the general model's
!> directions (a K_x entry), each mode's damping in closed form (ringing_init).
module test_fd_stick_ringing
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_stick_ringing, only: newmark_frequency, ringing_type, ringing_normal_force, ringing_init
   use fd_error, only: fd_error_type => error_type
   use fd_model, only: model_type, device_type
   use fd_names, only: law_hysteretic, law_velocity
   use fd_result, only: result_type
   use test_fd_helpers, only: pairs_of
   implicit none
   private

   public :: collect_stick_ringing

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   subroutine collect_stick_ringing(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("average acceleration: 2 atan(w / 2), no damping", test_average), &
                  new_unittest("linear acceleration: its cosine, unstable beyond sqrt(12)", test_linear), &
                  new_unittest("gamma > 1/2: damping (gamma - 1/2) w / 2 at small steps", test_damped), &
                  new_unittest("the frequency of the recursion run step by step", test_recursion), &
                  new_unittest("a bearing's observed N: spring and error at the largest", test_observed_force), &
                  new_unittest("node pairs and general directions: the same modes", test_general_modes) &
                  ]
   end subroutine collect_stick_ringing

   subroutine test_average(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: w, wt, z
      logical :: osc
      integer :: k

      do k = 1, 60
         w = 0.05_dp*k
         call newmark_frequency(w, 0.25_dp, 0.5_dp, wt, z, osc)
         call check(error, osc, "the average acceleration rule always oscillates")
         if (allocated(error)) return
         call check(error, abs(wt - 2*atan(w/2)) <= 4*epsilon(1.0_dp)*wt, "omega~ dt = 2 atan(omega dt / 2)")
         if (allocated(error)) return
         call check(error, abs(z) <= 4*epsilon(1.0_dp), "no numerical damping")
         if (allocated(error)) return
      end do
      ! the error the module reports, 1 - wt / w: 2.76 % at w = 0.59 (docs/theory.md)
      call newmark_frequency(0.59_dp, 0.25_dp, 0.5_dp, wt, z, osc)
      call check(error, abs(1 - wt/0.59_dp - 0.0275819_dp) < 1e-7_dp, "2.76 % at omega dt = 0.59")
   end subroutine test_average

   subroutine test_linear(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: w, wt, z
      logical :: osc
      integer :: k

      do k = 1, 34
         w = 0.1_dp*k                       ! up to 3.4 < sqrt(12) = 3.46
         call newmark_frequency(w, 1.0_dp/6, 0.5_dp, wt, z, osc)
         call check(error, osc, "oscillates below sqrt(12)")
         if (allocated(error)) return
         call check(error, abs(cos(wt) - (1 - w*w/(2*(1 + w*w/6)))) <= 8*epsilon(1.0_dp), &
                    "cos(omega~ dt) = 1 - w^2 / (2 (1 + w^2 / 6))")
         if (allocated(error)) return
      end do
      call newmark_frequency(3.5_dp, 1.0_dp/6, 0.5_dp, wt, z, osc)
      call check(error, .not. osc .and. wt == 0.0_dp, "not oscillating beyond sqrt(12) (unstable)")
   end subroutine test_linear

   subroutine test_damped(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: w, wt, z, gamma, beta
      logical :: osc

      gamma = 0.6_dp
      beta = 0.25_dp*(gamma + 0.5_dp)**2
      w = 1.0e-3_dp
      call newmark_frequency(w, beta, gamma, wt, z, osc)
      call check(error, osc .and. abs(z/((gamma - 0.5_dp)*w/2) - 1) < 1e-5_dp, &
                 "zeta ~ (gamma - 1/2) omega dt / 2 at a small step")
   end subroutine test_damped

   !> Free vibration of x'' + w^2 x = 0 (dt = 1) by Newmark's recursion, whose displacements
   !> follow u(k+1) = 2 r cos(th) u(k) - r^2 u(k-1) with r = exp(-zeta wt), th = wt: then
   !> (u(k)^2 - 2 r cos(th) u(k) u(k-1) + r^2 u(k-1)^2) / r^(2k) stays constant. With
   !> newmark_frequency's wt and zeta it does, to about 1e-12 over 20 000 steps; a frequency
   !> off by 1e-9 (relative) moves it by 2e-9.
   subroutine test_recursion(error)
      integer, parameter :: nsteps = 20000
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: cases(3, 5), w, beta, gamma, wt, z, u, v, a, u1, v1, a1, r, q, q0, dev, up
      integer :: i, k
      logical :: osc

      ! w, beta, gamma
      cases(:, 1) = [0.59_dp, 0.25_dp, 0.5_dp]
      cases(:, 2) = [1.7_dp, 0.25_dp, 0.5_dp]
      cases(:, 3) = [0.9_dp, 1.0_dp/6, 0.5_dp]
      cases(:, 4) = [0.3_dp, 0.3025_dp, 0.6_dp]
      cases(:, 5) = [2.5_dp, 0.3025_dp, 0.6_dp]
      do i = 1, size(cases, 2)
         w = cases(1, i); beta = cases(2, i); gamma = cases(3, i)
         call newmark_frequency(w, beta, gamma, wt, z, osc)
         r = exp(-z*wt)
         u = 1.0_dp; v = 0.0_dp; a = -w*w*u
         up = u
         q0 = 0; dev = 0
         do k = 1, nsteps
            u1 = u + v + (0.5_dp - beta)*a
            v1 = v + (1 - gamma)*a
            a1 = -w*w*u1/(1 + beta*w*w)
            u1 = u1 + beta*a1
            v1 = v1 + gamma*a1
            up = u
            u = u1; v = v1; a = a1
            q = (u*u - 2*r*cos(wt)*u*up + r*r*up*up)/r**(2*k)
            if (k == 1) q0 = q
            dev = max(dev, abs(q/q0 - 1))
            if (r**(2*k) < 1e-200_dp) exit
         end do
         call check(error, dev < 1e-10_dp, "the recursion's invariant holds with newmark_frequency's "// &
                    "frequency and damping")
         if (allocated(error)) return
      end do
   end subroutine test_recursion

   !> A hysteretic bearing component (P, mu, f) watched at the deck's P on a mode of mass mr;
   !> the observer sees its N reach 0.5 P and 1.5 P: the spring is 1.5 P mu / f, omega its
   !> mode's, the frequency error average acceleration's 1 - 2 atan(x / 2) / x at x = omega dt1,
   !> the drift |error| omega, the margin's capacity 0.5 P mu; a range that does not grow
   !> leaves the watch as it is.
   subroutine test_observed_force(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res
      type(ringing_type) :: rg
      real(dp), parameter :: p = 1.0e5_dp, mu = 0.2_dp, f = 1.0e-4_dp, mr = 2.0e4_dp, dt1 = 1.0e-3_dp
      real(dp) :: k, x, e

      model%n_devices = 1
      model%dev = [device_type(law=law_hysteretic, p=p, mu=mu, f=f, partner=2, component=1)]
      res%n_bearings = 1
      res%bearing_n_min = [p]
      res%bearing_n_max = [p]
      res%stick_freq_error = [0.0_dp]
      k = p*mu/f
      rg%n = 1
      rg%dev = [1]
      rg%bearing = [1]
      rg%nrange = reshape([p, p], [2, 1])
      rg%k = [k]
      rg%mr = [mr]
      rg%omega = [sqrt(k/mr)]
      rg%c_fixed = [0.0_dp]
      rg%drift = [0.0_dp]
      rg%pmu = [p*mu]
      rg%pfloor = [p*mu]
      rg%dt1 = dt1
      rg%beta = 0.25_dp
      rg%gamma = 0.5_dp
      call ringing_normal_force(model, rg, res)
      call check(error, rg%k(1) == k .and. res%stick_freq_error(1) == 0.0_dp, "the deck's range kept")
      if (allocated(error)) return
      res%bearing_n_min = [0.5_dp*p]
      res%bearing_n_max = [1.5_dp*p]
      call ringing_normal_force(model, rg, res)
      x = sqrt(1.5_dp*k/mr)*dt1
      e = 1.0_dp - 2.0_dp*atan(x/2.0_dp)/x
      call check(error, abs(rg%k(1) - 1.5_dp*k) <= 1e-12_dp*k, "the spring at the largest N")
      if (allocated(error)) return
      call check(error, abs(res%stick_freq_error(1) - e) <= 1e-9_dp*e, "the frequency error at the largest N")
      if (allocated(error)) return
      call check(error, abs(rg%drift(1) - e*x/dt1) <= 1e-9_dp*e*x/dt1, "the drift at the largest N")
      if (allocated(error)) return
      call check(error, abs(rg%pmu(1) - 0.5_dp*p*mu) <= 1e-12_dp*p*mu .and. rg%pfloor(1) == rg%pmu(1), &
                 "the capacities at the smallest N")
      if (allocated(error)) return
      call check(error, abs(rg%c_fixed(1)) <= 1e-12_dp, "no damping of average acceleration")
   end subroutine test_observed_force

   !> Two masses (2 and 1 kg) on springs 800 (1 to the table) and 300 N/m (2 to 1), hysteretic
   !> devices 1 (1 to the table, k = 2000 N/m) and 2 (2 to 1, k = 1000 N/m) and a velocity-law
   !> device 3 (2 to 1): the devices watched, their modes' masses, frequencies, damping and
   !> band devices are the same through the node pairs and through the general model's
   !> directions (a K_x entry of 0 takes that path). The closed forms: device 1's mode is node 1
   !> alone (m_r = 2, phi' K phi = 800 + 300), device 2's moves node 2 by 2/3 and node 1 by
   !> -1/3 (m_r = 2/3, phi' K phi = 300 + 800 / 9); device 3 moves with both, (b_3' phi)^2 = 1.
   subroutine test_general_modes(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(result_type) :: res, res_g
      type(ringing_type) :: rg, rg_g
      type(fd_error_type), allocatable :: err
      real(dp), parameter :: a0 = 0.3_dp, a1 = 2.0e-3_dp, dt1 = 0.01_dp, gamma = 0.6_dp
      real(dp), parameter :: beta = 0.25_dp*(gamma + 0.5_dp)**2
      real(dp), parameter :: mr(2) = [2.0_dp, 2.0_dp/3.0_dp], kk(2) = [2000.0_dp, 1000.0_dp]
      real(dp), parameter :: ek(2) = [1100.0_dp, 300.0_dp + 800.0_dp/9.0_dp]
      real(dp) :: omega, wt, zn
      logical :: osc
      integer :: q

      model%n_dof = 2
      model%mass = [2.0_dp, 1.0_dp]
      model%n_springs = 2
      model%spring_i = [1, 2]
      model%spring_j = [0, 1]
      model%spring_k = [800.0_dp, 300.0_dp]
      model%n_devices = 3
      model%dev = [device_type(node_i=1, node_j=0, law=law_hysteretic, p=10.0_dp, mu=0.2_dp, f=1.0e-3_dp), &
                   device_type(node_i=2, node_j=1, law=law_hysteretic, p=5.0_dp, mu=0.2_dp, f=1.0e-3_dp), &
                   device_type(node_i=2, node_j=1, law=law_velocity, p=5.0_dp, mu=0.2_dp)]
      call pairs_of(model)
      allocate (res%stick_freq_error(3), res_g%stick_freq_error(3))
      res%stick_freq_error = 0.0_dp
      res_g%stick_freq_error = 0.0_dp
      call ringing_init(model, dt1, beta, gamma, a0, a1, rg, res, err)
      call check(error, .not. allocated(err), "node pairs: an error")
      if (allocated(error)) return
      model%n_kx = 1
      model%kx_i = [1]
      model%kx_j = [1]
      model%kx_v = [0.0_dp]
      call ringing_init(model, dt1, beta, gamma, a0, a1, rg_g, res_g, err)
      call check(error, .not. allocated(err), "general directions: an error")
      if (allocated(error)) return
      call check(error, rg%n == 2 .and. rg_g%n == 2 .and. all(rg%dev == [1, 2]) .and. all(rg_g%dev == [1, 2]), &
                 "the devices with a sticking spring")
      if (allocated(error)) return
      call check(error, all(rg%first == [1, 2, 3]) .and. all(rg_g%first == [1, 2, 3]) .and. &
                 all(rg%band_dev == [3, 3]) .and. all(rg_g%band_dev == [3, 3]), "device 3 moves with both modes")
      if (allocated(error)) return
      call check(error, all(abs(rg%band_shape - 1.0_dp) <= 1e-15_dp) .and. &
                 all(abs(rg_g%band_shape - 1.0_dp) <= 1e-15_dp), "(b_3' phi)^2 = 1")
      if (allocated(error)) return
      do q = 1, 2
         omega = sqrt(kk(q)/mr(q))
         call newmark_frequency(omega*dt1, beta, gamma, wt, zn, osc)
         call check(error, abs(rg%mr(q) - mr(q)) <= 1e-15_dp*mr(q) .and. abs(rg_g%mr(q) - mr(q)) <= 1e-15_dp*mr(q), &
                    "the mode's mass")
         if (allocated(error)) return
         call check(error, abs(rg%omega(q) - omega) <= 1e-14_dp*omega .and. &
                    abs(rg_g%omega(q) - omega) <= 1e-14_dp*omega, "the mode's frequency sqrt(k / m_r)")
         if (allocated(error)) return
         call check(error, abs(res%stick_freq_error(q) - (1 - wt/(omega*dt1))) <= 1e-12_dp .and. &
                    abs(res_g%stick_freq_error(q) - res%stick_freq_error(q)) <= 1e-12_dp, "Newmark's error on it")
         if (allocated(error)) return
         call check(error, abs(rg%drift(q) - abs(res%stick_freq_error(q))*omega) <= 1e-12_dp*omega .and. &
                    abs(rg_g%drift(q) - rg%drift(q)) <= 1e-12_dp*omega, "its drift")
         if (allocated(error)) return
         call check(error, abs(rg%c_fixed(q) - (a0*mr(q) + a1*ek(q) + 2*mr(q)*omega*zn)) <= 1e-12_dp*rg%c_fixed(q) &
                    .and. abs(rg_g%c_fixed(q) - rg%c_fixed(q)) <= 1e-12_dp*rg%c_fixed(q), &
                    "a0 m_r + a1 phi' K phi + Newmark's own 2 m_r omega zeta")
         if (allocated(error)) return
         call check(error, rg%pmu(q) == model%dev(q)%p*model%dev(q)%mu .and. rg_g%pmu(q) == rg%pmu(q) .and. &
                    rg%pfloor(q) == rg%pmu(q) .and. rg_g%pfloor(q) == rg%pmu(q), "the capacities at the deck's p")
         if (allocated(error)) return
      end do
      call check(error, res%stick_checked .and. res_g%stick_checked, "checked")
   end subroutine test_general_modes

end module test_fd_stick_ringing
