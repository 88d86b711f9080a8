!> Unit tests of the dense one-step problem of Moreau-Jean time stepping (fd_dense_impulse):
!> against the band solver of node-pair devices (fd_impulse_solver, an independent method:
!> sticking groups, active set), against closed forms for a device of a general direction,
!> and the acceleration problem at the end of a step.
module test_fd_dense_impulse
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_model, only: model_type, device_type, law_coulomb
   use fd_kinematics, only: append_device
   use fd_impulse_solver, only: impulse_solver, solver_setup, solve_impulses
   use fd_dense_impulse, only: dense_impulse, dense_setup, dense_factor, dense_solve, dense_acceleration, &
                               dense_k_times
   use test_fd_helpers, only: check_close, pairs_of
   implicit none
   private

   public :: collect_dense_impulse

contains

   subroutine collect_dense_impulse(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("node pairs: the band solver's solution", test_pairs), &
                  new_unittest("a general direction: stick and slide in closed form", test_general), &
                  new_unittest("acceleration: a slider keeps P mu, a device at rest holds", test_acceleration), &
                  new_unittest("K includes the stiffness beyond springs", test_kx) &
                  ]
   end subroutine collect_dense_impulse

   !> A chain of three masses on springs, devices from mass 1 to the table, 2-1 and 3-1.
   subroutine chain(model)
      type(model_type), intent(out) :: model

      model%n_dof = 3
      model%mass = [2.0_dp, 1.0_dp, 1.5_dp]
      model%n_springs = 3
      model%spring_i = [1, 2, 3]
      model%spring_j = [0, 1, 2]
      model%spring_k = [800.0_dp, 300.0_dp, 500.0_dp]
      model%n_devices = 3
      model%dev = [device_type(node_i=1, node_j=0, law=law_coulomb, p=10.0_dp, mu=0.2_dp), &
                   device_type(node_i=2, node_j=1, law=law_coulomb, p=5.0_dp, mu=0.2_dp), &
                   device_type(node_i=3, node_j=1, law=law_coulomb, p=4.0_dp, mu=0.25_dp)]
      call pairs_of(model)
   end subroutine chain

   subroutine test_pairs(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(dense_impulse) :: di
      type(impulse_solver) :: p
      type(fd_error_type), allocatable :: err
      real(dp) :: r(3), v1(3), v2(3), lam(3), w(3), g(3), alpha, beta
      integer :: sigma(3), c, i
      real(dp), parameter :: rs(3, 3) = reshape([1.0_dp, -0.5_dp, 2.0_dp, 0.01_dp, 0.02_dp, -0.01_dp, &
                                                 -3.0_dp, 0.2_dp, 0.3_dp], [3, 3])

      call chain(model)
      alpha = 1.0_dp
      beta = 1.0e-4_dp
      g = 0.05_dp*[2.0_dp, 1.0_dp, 1.0_dp]
      call dense_setup(di, model, err)
      if (.not. allocated(err)) call dense_factor(di, alpha, beta, err)
      call check(error, .not. allocated(err), "dense setup")
      if (allocated(error)) return
      call solver_setup(p, model%mass, model%spring_i, model%spring_j, model%spring_k, [1, 2, 3], [0, 1, 1], &
                        [2.0_dp, 1.0_dp, 1.0_dp], err)
      call check(error, .not. allocated(err), "band setup")
      if (allocated(error)) return
      ! three right-hand sides: sliding devices, all stuck, a mix (v1 to 1e-12 of the velocity
      ! scale r / alpha m, m >= 1)
      do c = 1, 3
         r = rs(:, c)
         call dense_solve(di, r, g, v1, lam, w, sigma, err)
         call check(error, .not. allocated(err), "dense solve")
         if (allocated(error)) return
         call solve_impulses(p, r, abs(r), alpha, beta, g, v2, err)
         call check(error, .not. allocated(err), "band solve")
         if (allocated(error)) return
         do i = 1, 3
            call check_close(error, v1(i), v2(i), 1.0e-12_dp*maxval(abs(r))/alpha, "v1 against the band solver", &
                             absolute=.true.)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_pairs

   !> One mass m = 2 to the table by a spring-free device of direction b = 2 e_1 (s = 2 u):
   !> W = m, v1 = (r - 2 lam) / m. r = 10, g = 3: sticking needs lam = 5 > 3, so it slides,
   !> lam = 3, v1 = 2, b'v1 = 4 > 0. g = 6: it sticks, lam = 5, v1 = 0.
   subroutine test_general(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(dense_impulse) :: di
      type(fd_error_type), allocatable :: err
      real(dp) :: v1(1), lam(1), w(1)
      integer :: sigma(1), stat

      model%n_dof = 1
      model%mass = [2.0_dp]
      model%n_springs = 0
      allocate (model%spring_i(0), model%spring_j(0), model%spring_k(0))
      model%n_devices = 0
      allocate (model%dev(0))
      call pairs_of(model)
      call append_device(model, device_type(law=law_coulomb, p=1.0_dp, mu=1.0_dp), [1], [2.0_dp], stat)
      call dense_setup(di, model, err)
      if (.not. allocated(err)) call dense_factor(di, 1.0_dp, 0.0_dp, err)
      call check(error, .not. allocated(err), "setup")
      if (allocated(error)) return
      call dense_solve(di, [10.0_dp], [3.0_dp], v1, lam, w, sigma, err)
      call check(error, .not. allocated(err), "solve")
      if (allocated(error)) return
      call check_close(error, lam(1), 3.0_dp, 1.0e-14_dp, "sliding impulse")
      if (allocated(error)) return
      call check_close(error, v1(1), 2.0_dp, 1.0e-14_dp, "sliding velocity")
      if (allocated(error)) return
      call check(error, sigma(1) == 1 .and. abs(w(1) - 4.0_dp) <= 1.0e-14_dp, "slides its way")
      if (allocated(error)) return
      call dense_solve(di, [10.0_dp], [6.0_dp], v1, lam, w, sigma, err)
      call check(error, .not. allocated(err), "solve")
      if (allocated(error)) return
      call check_close(error, lam(1), 5.0_dp, 1.0e-14_dp, "sticking impulse")
      if (allocated(error)) return
      call check(error, sigma(1) == 0 .and. abs(v1(1)) <= 1.0e-14_dp, "sticks")
   end subroutine test_general

   !> The chain at rest but for forces f: device 1 slides (+) with P mu = 2 whatever f; the
   !> others at rest: with f = (0, 0.1, -0.2) they hold (the force each needs is within its
   !> bound), with f = (0, 5, 0) device 2 starts to slide (+).
   subroutine test_acceleration(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(dense_impulse) :: di
      type(fd_error_type), allocatable :: err
      real(dp) :: acc(3), force(3), pmu(3)
      integer :: sa(3)

      call chain(model)
      pmu = [2.0_dp, 1.0_dp, 1.0_dp]
      call dense_setup(di, model, err)
      call check(error, .not. allocated(err), "setup")
      if (allocated(error)) return
      call dense_acceleration(di, [0.0_dp, 0.1_dp, -0.2_dp], pmu, [1, 0, 0], acc, force, sa, err)
      call check(error, .not. allocated(err), "acceleration")
      if (allocated(error)) return
      call check(error, all(sa == [1, 0, 0]) .and. force(1) == 2.0_dp, "slider keeps P mu, others hold")
      if (allocated(error)) return
      ! held: masses 2 and 3 move with mass 1, a = (0 + 0.1 - 0.2 - 2) / 4.5
      call check_close(error, acc(2), -2.1_dp/4.5_dp, 1.0e-14_dp, "held group's acceleration")
      if (allocated(error)) return
      call check_close(error, acc(3), acc(1), 1.0e-14_dp, "held device 3")
      if (allocated(error)) return
      call dense_acceleration(di, [0.0_dp, 5.0_dp, 0.0_dp], pmu, [1, 0, 0], acc, force, sa, err)
      call check(error, .not. allocated(err), "acceleration")
      if (allocated(error)) return
      call check(error, sa(2) == 1 .and. abs(force(2) - 1.0_dp) <= 1.0e-14_dp, "device 2 starts to slide +")
   end subroutine test_acceleration

   !> K x with an entry of K_x beyond the springs (1 to 2, value 50).
   subroutine test_kx(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(dense_impulse) :: di
      type(fd_error_type), allocatable :: err
      real(dp) :: y(3)

      call chain(model)
      model%n_kx = 1
      model%kx_i = [1]
      model%kx_j = [2]
      model%kx_v = [50.0_dp]
      call dense_setup(di, model, err)
      call check(error, .not. allocated(err), "setup")
      if (allocated(error)) return
      y = 0.0_dp
      call dense_k_times(di, [0.0_dp, 1.0_dp, 0.0_dp], y, 1.0_dp, 0.0_dp)
      ! column 2 of K: springs (-300, 300 + 500, -500) plus K_x's 50 at (1, 2)
      call check(error, all(abs(y - [-250.0_dp, 800.0_dp, -500.0_dp]) <= 1.0e-12_dp), "K column 2")
   end subroutine test_kx

end module test_fd_dense_impulse
