!> Unit tests of the dense one-step problem of Moreau-Jean time stepping (fd_dense_impulse):
!> against the band solver of node-pair devices (fd_impulse_solver, an independent method:
!> sticking groups, active set), against closed forms for a device of a general direction,
!> and the acceleration problem at the end of a step; the banded form against the dense one.
module test_fd_dense_impulse
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_model, only: model_type, device_type, law_coulomb
   use fd_kinematics, only: append_device
   use fd_impulse_solver, only: impulse_solver, solver_setup, solve_impulses
   use fd_dense_impulse, only: dense_impulse, dense_setup, dense_factor, dense_solve, dense_acceleration, &
                               dense_k_times, impulse_banded, impulse_bandwidth, banded_min_dofs
   use fd_names, only: linear_system_auto, linear_system_dense, linear_system_banded
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
                  new_unittest("K includes the stiffness beyond springs", test_kx), &
                  new_unittest("K x with beta = 0 does not read y (a NaN there)", test_k_times_unread), &
                  new_unittest("banded form: the dense form's steps, general devices and K_x", test_banded_general), &
                  new_unittest("banded form: the dense form's steps with a planar bearing", test_banded_bearing), &
                  new_unittest("banded form: W = alpha M alone (beta = 0)", test_banded_inertia), &
                  new_unittest("banded form: chosen by linear_system and size", test_banded_choice) &
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

   !> y = K x with beta = 0 takes nothing of y, which may be memory never set (a NaN there
   !> gave 0 NaN = NaN): the dense form's and the banded form's both give K's column.
   subroutine test_k_times_unread(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(dense_impulse) :: di
      type(fd_error_type), allocatable :: err
      real(dp) :: y(3)
      integer :: form

      do form = 1, 2
         call chain(model)
         call dense_setup(di, model, err, banded=form == 2)
         call check(error, .not. allocated(err), "setup")
         if (allocated(error)) return
         y = ieee_value(y, ieee_quiet_nan)
         call dense_k_times(di, [0.0_dp, 1.0_dp, 0.0_dp], y, 1.0_dp, 0.0_dp)
         call check(error, all(ieee_is_finite(y)), "K x finite whatever y held")
         if (allocated(error)) return
         ! column 2 of the chain's K: springs (-300, 300 + 500, -500)
         call check(error, all(abs(y - [-300.0_dp, 800.0_dp, -500.0_dp]) <= 1.0e-12_dp), "K column 2")
         if (allocated(error)) return
      end do
   end subroutine test_k_times_unread

   !> Nine DOFs, three a floor (springs from each DOF to the one a floor below, the first
   !> floor's to the table) and K_x coupling neighbouring DOFs (a spring written as entries),
   !> and four general devices of one to three terms; with bearing, devices 1 and 2 (DOFs 1
   !> and 2 to the table) are one planar bearing's two components.
   subroutine general_model(model, bearing)
      type(model_type), intent(out) :: model
      logical, intent(in) :: bearing
      integer :: i, stat, p1, p2

      model%n_dof = 9
      model%mass = [2.0_dp, 1.0_dp, 1.5_dp, 2.5_dp, 1.2_dp, 0.8_dp, 1.1_dp, 3.0_dp, 1.7_dp]
      model%n_springs = 9
      model%spring_i = [(i, i=1, 9)]
      model%spring_j = [(max(i - 3, 0), i=1, 9)]
      model%spring_k = [(400.0_dp + 37.0_dp*i, i=1, 9)]
      model%n_kx = 17
      model%kx_i = [(i, i=1, 9), (i, i=1, 8)]
      model%kx_j = [(i, i=1, 9), (i + 1, i=1, 8)]
      model%kx_v = [(merge(1.0_dp, 2.0_dp, i == 1 .or. i == 9)*60.0_dp, i=1, 9), (-60.0_dp, i=1, 8)]
      model%n_devices = 0
      allocate (model%dev(0))
      call pairs_of(model)
      p1 = 0
      p2 = 0
      if (bearing) then
         p1 = 2
         p2 = 1
      end if
      call append_device(model, device_type(law=law_coulomb, p=10.0_dp, mu=0.2_dp, partner=p1), [1], [1.0_dp], stat)
      call append_device(model, device_type(law=law_coulomb, p=10.0_dp, mu=0.2_dp, partner=p2), [2], [1.0_dp], stat)
      call append_device(model, device_type(law=law_coulomb, p=6.0_dp, mu=0.3_dp), [7, 4, 9], &
                         [1.0_dp, -1.0_dp, 0.3_dp], stat)
      call append_device(model, device_type(law=law_coulomb, p=3.0_dp, mu=0.25_dp), [5, 6], [1.0_dp, -2.0_dp], stat)
   end subroutine general_model

   !> The dense and the banded form of one model over right-hand sides that make every device
   !> stick, every one slide, and mixes: v1, the impulses, the statuses and the acceleration
   !> problem agree to 1e-12 of their scales; K x agrees.
   subroutine compare_forms(error, bearing)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in) :: bearing
      type(model_type) :: model
      type(dense_impulse) :: dd, db
      type(fd_error_type), allocatable :: err
      real(dp) :: r(9), v1(9), v2(9), lam1(4), lam2(4), w1(4), w2(4), g(4), acc1(9), acc2(9), f1(4), f2(4)
      real(dp) :: y1(9), y2(9), sc
      integer :: s1(4), s2(4), a1(4), a2(4), c, i
      real(dp), parameter :: amp(4) = [1.0e-3_dp, 0.05_dp, 0.5_dp, 20.0_dp]

      call general_model(model, bearing)
      call dense_setup(dd, model, err)
      if (.not. allocated(err)) call dense_factor(dd, 1.01_dp, 2.5e-5_dp, err)
      call check(error, .not. allocated(err), "dense form's setup")
      if (allocated(error)) return
      call dense_setup(db, model, err, banded=.true.)
      if (.not. allocated(err)) call dense_factor(db, 1.01_dp, 2.5e-5_dp, err)
      call check(error, .not. allocated(err), "banded form's setup")
      if (allocated(error)) return
      call check(error, impulse_bandwidth(db) >= 1 .and. impulse_bandwidth(db) < 8 .and. &
                 impulse_bandwidth(dd) == -1, "a band narrower than the matrix")
      if (allocated(error)) return
      g = 0.01_dp*model%dev%p*model%dev%mu
      do c = 1, 4
         r = [(amp(c)*sin(1.7_dp*i + c), i=1, 9)]
         call dense_solve(dd, r, g, v1, lam1, w1, s1, err)
         if (.not. allocated(err)) call dense_solve(db, r, g, v2, lam2, w2, s2, err)
         call check(error, .not. allocated(err), "solves")
         if (allocated(error)) return
         sc = maxval(abs(r))
         call check(error, maxval(abs(v1 - v2)) <= 1.0e-12_dp*sc, "v1 of the two forms")
         if (allocated(error)) return
         call check(error, maxval(abs(lam1 - lam2)) <= 1.0e-12_dp*max(sc, maxval(g)), "impulses of the two forms")
         if (allocated(error)) return
         call check(error, all(s1 == s2), "statuses of the two forms")
         if (allocated(error)) return
         call dense_acceleration(dd, 100.0_dp*r, g/0.01_dp, s1, acc1, f1, a1, err, w1)
         if (.not. allocated(err)) call dense_acceleration(db, 100.0_dp*r, g/0.01_dp, s2, acc2, f2, a2, err, w2)
         call check(error, .not. allocated(err), "acceleration problems")
         if (allocated(error)) return
         call check(error, maxval(abs(acc1 - acc2)) <= 1.0e-11_dp*maxval(abs(acc1)) .and. &
                    maxval(abs(f1 - f2)) <= 1.0e-11_dp*maxval(abs(f1)) .and. all(a1 == a2), &
                    "end accelerations and forces of the two forms")
         if (allocated(error)) return
         if (c == 1) call check(error, all(s1 == 0), "small loads: every device sticks")
         if (c == 4) call check(error, all(s1 /= 0), "large loads: every device slides")
         if (allocated(error)) return
      end do
      y1 = 1.0_dp
      y2 = 1.0_dp
      call dense_k_times(dd, r, y1, 2.0_dp, -0.5_dp)
      call dense_k_times(db, r, y2, 2.0_dp, -0.5_dp)
      call check(error, maxval(abs(y1 - y2)) <= 1.0e-12_dp*maxval(abs(y1)), "K x of the two forms")
   end subroutine compare_forms

   subroutine test_banded_general(error)
      type(error_type), allocatable, intent(out) :: error
      call compare_forms(error, .false.)
   end subroutine test_banded_general

   subroutine test_banded_bearing(error)
      type(error_type), allocatable, intent(out) :: error
      call compare_forms(error, .true.)
   end subroutine test_banded_bearing

   !> beta = 0: W = alpha M, no factor (the general direction of test_general: r = 10, g = 3,
   !> alpha = 1: it slides, lam = 3).
   subroutine test_banded_inertia(error)
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
      call dense_setup(di, model, err, banded=.true.)
      if (.not. allocated(err)) call dense_factor(di, 1.0_dp, 0.0_dp, err)
      if (.not. allocated(err)) call dense_solve(di, [10.0_dp], [3.0_dp], v1, lam, w, sigma, err)
      call check(error, .not. allocated(err), "setup and solve")
      if (allocated(error)) return
      call check(error, abs(lam(1) - 3.0_dp) <= 1.0e-14_dp .and. abs(v1(1) - 2.0_dp) <= 1.0e-14_dp .and. &
                 sigma(1) == 1, "slides: lam = 3, v1 = 2")
   end subroutine test_banded_inertia

   !> 'dense' and 'banded' force the form; 'auto' takes the banded one from banded_min_dofs on.
   subroutine test_banded_choice(error)
      type(error_type), allocatable, intent(out) :: error

      call check(error, .not. impulse_banded(100000, linear_system_dense) .and. &
                 impulse_banded(2, linear_system_banded) .and. &
                 .not. impulse_banded(banded_min_dofs - 1, linear_system_auto) .and. &
                 impulse_banded(banded_min_dofs, linear_system_auto), "the form chosen")
   end subroutine test_banded_choice

end module test_fd_dense_impulse
