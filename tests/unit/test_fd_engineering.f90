!> Unit tests of the engineering outputs (fd_engineering, fd_matrices%natural_modes): the
!> natural periods and shapes of a uniform chain against the closed form, stuck and free,
!> a rigid and an unrestrained system, the modal damping ratios of Rayleigh damping, and
!> the storey drifts and shears of a hand-computed state.
module test_fd_engineering
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_model, only: model_type, integration_type, law_velocity, law_hysteretic, damping_rayleigh, &
                       system_stuck, system_free
   use fd_excitation, only: excitation_type, excitation_none
   use fd_matrices, only: modes_type, natural_modes, stiffness_matrix, damping_matrix, modes_flexible, &
                          modes_rigid, modes_unrestrained, natural_modes_sparse
   use fd_engineering, only: engineering_type, engineering_init, storey_values, observe_engineering, &
                             observe_floor_accelerations
   use test_fd_helpers, only: check_close, pairs_of
   implicit none
   private

   public :: collect_engineering

   real(dp), parameter :: pi = acos(-1.0_dp)
   real(dp), parameter :: m = 2.0e5_dp, k = 3.0e8_dp   !! a uniform shear building: kg, N/m

contains

   subroutine collect_engineering(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("uniform chain, free: closed-form periods and shapes", test_chain_free), &
                  new_unittest("uniform chain, stuck: a rigid link and hysteretic springs", test_chain_stuck), &
                  new_unittest("long chain: the band eigensolver", test_chain_long), &
                  new_unittest("rigid and unrestrained systems", test_rigid), &
                  new_unittest("modal damping ratios of Rayleigh damping", test_rayleigh_xi), &
                  new_unittest("storey drifts and shears of a hand-computed state", test_storeys), &
                  new_unittest("large-model modes (no n x n matrix) = dense modes", test_sparse_modes), &
                  new_unittest("floor corner accelerations: the largest over the corners", test_corner_acc) &
                  ]
   end subroutine collect_engineering

   !> n equal masses m on a chain of n equal springs k from the table, devices as given
   !> (node_i, node_j, law; P mu = 1e5 N, f = P mu / k_dev with k_dev = k).
   subroutine chain(model, n, devices, laws)
      type(model_type), intent(out) :: model
      integer, intent(in) :: n
      integer, intent(in) :: devices(:, :)
      integer, intent(in) :: laws(:)
      integer :: d, i

      model%n_dof = n
      model%mass = [(m, i=1, n)]
      model%u0 = [(0.0_dp, i=1, n)]
      model%v0 = model%u0
      model%n_springs = n
      model%spring_i = [(i, i=1, n)]
      model%spring_j = [(i - 1, i=1, n)]
      model%spring_k = [(k, i=1, n)]
      model%n_devices = size(devices, 2)
      allocate (model%dev(model%n_devices))
      do d = 1, model%n_devices
         model%dev(d)%node_i = devices(1, d)
         model%dev(d)%node_j = devices(2, d)
         model%dev(d)%law = laws(d)
         model%dev(d)%p = 1.0e5_dp
         model%dev(d)%mu = 1.0_dp
         model%dev(d)%f = 1.0e5_dp/k
      end do
      call pairs_of(model)
   end subroutine chain

   !> The modes of a model (no damping).
   subroutine modes_of(model, system, modes, error)
      type(model_type), intent(in) :: model
      integer, intent(in) :: system
      type(modes_type), intent(out) :: modes
      type(error_type), allocatable, intent(out) :: error
      type(fd_error_type), allocatable :: err
      real(dp), allocatable :: kk(:, :), c(:, :)

      allocate (kk(model%n_dof, model%n_dof), c(model%n_dof, model%n_dof))
      call stiffness_matrix(model, kk)
      c = 0.0_dp
      call natural_modes(model, kk, c, system, model%n_dof, modes, err)
      call check(error, .not. allocated(err), 'natural_modes fails')
   end subroutine modes_of

   !> Mode r of a uniform chain of n masses fixed at the table (stiffness factor s: each
   !> spring s k): w_r = 2 sqrt(s k / m) sin((2r - 1) pi / (2 (2n + 1))),
   !> phi_r(j) = sin(j (2r - 1) pi / (2n + 1)).
   subroutine check_chain_modes(error, modes, n, s, what)
      type(error_type), allocatable, intent(out) :: error
      type(modes_type), intent(in) :: modes
      integer, intent(in) :: n
      real(dp), intent(in) :: s
      character(len=*), intent(in) :: what
      real(dp) :: w, phi(n)
      integer :: r, j

      call check(error, modes%status == modes_flexible .and. modes%nq == n, what//': status and modes')
      if (allocated(error)) return
      do r = 1, n
         w = 2.0_dp*sqrt(s*k/m)*sin((2*r - 1)*pi/(2.0_dp*(2*n + 1)))
         call check_close(error, modes%period(r), 2.0_dp*pi/w, 1.0e-12_dp, what//': period')
         if (allocated(error)) return
         phi = [(sin(j*(2*r - 1)*pi/(2*n + 1)), j=1, n)]
         phi = phi/phi(maxloc(abs(phi), 1))
         do j = 1, n
            call check_close(error, modes%shape(size(modes%shape, 1) - n + j, r), phi(j), 1.0e-10_dp, &
                             what//': shape', absolute=.true.)
            if (allocated(error)) return
         end do
      end do
      call check_close(error, sum(modes%mass_ratio), real(n, dp)/size(modes%shape, 1), 1.0e-12_dp, &
                       what//': effective masses add up to the moving mass')
   end subroutine check_chain_modes

   subroutine test_chain_free(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(modes_type) :: modes

      ! a velocity-law device at the base does not enter the free system
      call chain(model, 5, reshape([1, 0], [2, 1]), [law_velocity])
      call modes_of(model, system_free, modes, error)
      if (allocated(error)) return
      call check_chain_modes(error, modes, 5, 1.0_dp, 'free chain')
   end subroutine test_chain_free

   !> 80 floors, numbered from the roof down (the band path reorders them): every period,
   !> and every shape up to its sign (two components of equal magnitude and opposite sign
   !> make the sign of the "largest is +1" scaling depend on the numbering).
   subroutine test_chain_long(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(modes_type) :: modes
      real(dp) :: w, phi(80), got(80)
      integer :: i, j, r, n

      n = 80
      call chain(model, n, reshape([1, 0], [2, 1]), [law_velocity])
      do i = 1, n   ! DOF i is floor n + 1 - i; spring i joins floor i to floor i - 1
         model%spring_i(i) = n + 1 - i
         model%spring_j(i) = merge(0, n + 2 - i, i == 1)
      end do
      call modes_of(model, system_free, modes, error)
      if (allocated(error)) return
      call check(error, modes%nq == n .and. modes%n == n, 'every mode')
      if (allocated(error)) return
      do r = 1, n
         w = 2.0_dp*sqrt(k/m)*sin((2*r - 1)*pi/(2.0_dp*(2*n + 1)))
         call check_close(error, modes%period(r), 2.0_dp*pi/w, 1.0e-11_dp, 'period, band path')
         if (allocated(error)) return
         phi = [(sin(j*(2*r - 1)*pi/(2*n + 1)), j=1, n)]
         phi = phi/maxval(abs(phi))
         got = modes%shape(n:1:-1, r)
         got = got*sign(1.0_dp, dot_product(got, phi))
         call check_close(error, maxval(abs(got - phi)), 0.0_dp, 1.0e-9_dp, 'shape, band path', absolute=.true.)
         if (allocated(error)) return
      end do
   end subroutine test_chain_long

   subroutine test_chain_stuck(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(modes_type) :: modes
      integer :: i

      ! a velocity-law device holding DOF 1 to the table: DOFs 2..5 a chain of 4 from DOF 1
      call chain(model, 5, reshape([1, 0], [2, 1]), [law_velocity])
      call modes_of(model, system_stuck, modes, error)
      if (allocated(error)) return
      call check(error, all(modes%shape(1, :) == 0.0_dp), 'the held DOF does not move')
      if (allocated(error)) return
      call check_chain_modes(error, modes, 4, 1.0_dp, 'chain held at DOF 1')
      if (allocated(error)) return
      ! a hysteretic device beside every spring, sticking stiffness P mu / f = k: springs 2k
      call chain(model, 5, reshape([(i, i - 1, i=1, 5)], [2, 5]), [(law_hysteretic, i=1, 5)])
      call modes_of(model, system_stuck, modes, error)
      if (allocated(error)) return
      call check_chain_modes(error, modes, 5, 2.0_dp, 'chain with hysteretic devices')
   end subroutine test_chain_stuck

   subroutine test_rigid(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(modes_type) :: modes
      integer :: i

      ! every mass held to the table by velocity-law devices: no mode, not a period of 0 s
      call chain(model, 3, reshape([(i, 0, i=1, 3)], [2, 3]), [(law_velocity, i=1, 3)])
      call modes_of(model, system_stuck, modes, error)
      if (allocated(error)) return
      call check(error, modes%status == modes_rigid .and. modes%n == 0 .and. modes%nq == 0, 'rigid stuck system')
      if (allocated(error)) return
      ! free: no spring to the table (a sliding base): one rigid-body mode of infinite period
      call chain(model, 3, reshape([1, 0], [2, 1]), [law_velocity])
      model%spring_j(1) = 2
      model%spring_i(1) = 1
      model%spring_j(2) = 1
      model%spring_i(2) = 2
      model%spring_i(3) = 3
      model%spring_j(3) = 2
      call modes_of(model, system_free, modes, error)
      if (allocated(error)) return
      call check(error, modes%status == modes_unrestrained, 'unrestrained free system')
      if (allocated(error)) return
      call check(error, .not. ieee_is_finite(modes%period(1)) .and. modes%omega2(1) == 0.0_dp .and. &
                 ieee_is_finite(modes%period(2)), 'the rigid-body mode has an infinite period')
      if (allocated(error)) return
      call check_close(error, modes%mass_ratio(1), 1.0_dp, 1.0e-12_dp, 'the rigid-body mode carries every mass')
   end subroutine test_rigid

   subroutine test_rayleigh_xi(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(modes_type) :: modes
      type(fd_error_type), allocatable :: err
      real(dp), allocatable :: kk(:, :), c(:, :)
      real(dp) :: w
      integer :: r

      call chain(model, 4, reshape([1, 0], [2, 1]), [law_velocity])
      model%damping = damping_rayleigh
      model%rayleigh_a0 = 0.3_dp
      model%rayleigh_a1 = 2.0e-3_dp
      allocate (kk(4, 4), c(4, 4))
      call stiffness_matrix(model, kk)
      call damping_matrix(model, kk, 0.0_dp, c)
      call natural_modes(model, kk, c, system_free, 4, modes, err)
      call check(error, .not. allocated(err), 'natural_modes fails')
      if (allocated(error)) return
      do r = 1, 4
         w = 2.0_dp*pi/modes%period(r)
         call check_close(error, modes%xi(r), 0.3_dp/(2.0_dp*w) + 2.0e-3_dp*w/2.0_dp, 1.0e-12_dp, &
                          'xi_r = a0 / (2 w_r) + a1 w_r / 2')
         if (allocated(error)) return
      end do
   end subroutine test_rayleigh_xi

   !> Three DOFs: springs (1,0) k, (2,1) k, (1,2) k/2 (written from the lower node), (3,2) k;
   !> devices (2,1) F1, (1,2) F2 (reversed), (1,0) F3; storeys (1,0), (2,1), (3,2).
   subroutine test_storeys(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(engineering_type) :: eng
      type(fd_error_type), allocatable :: err
      real(dp) :: u(3), v(3), f(3), drift(3), shear(3), base, a1, exp_shear(3), exp_base

      model%n_dof = 3
      model%mass = [1.0_dp, 1.0_dp, 1.0_dp]
      model%n_springs = 4
      model%spring_i = [1, 2, 1, 3]
      model%spring_j = [0, 1, 2, 2]
      model%spring_k = [k, k, k/2, k]
      model%n_devices = 3
      allocate (model%dev(3))
      model%dev(1)%node_i = 2; model%dev(1)%node_j = 1
      model%dev(2)%node_i = 1; model%dev(2)%node_j = 2
      model%dev(3)%node_i = 1; model%dev(3)%node_j = 0
      call pairs_of(model)
      model%damping = damping_rayleigh
      a1 = 1.0e-3_dp
      model%rayleigh_a0 = 0.5_dp
      model%rayleigh_a1 = a1
      model%n_storeys = 3
      model%storey_i = [1, 2, 3]
      model%storey_j = [0, 1, 2]
      model%storey_height = [3.0_dp, 0.0_dp, 3.0_dp]
      exc%kind = excitation_none
      opts%n_modes = 0
      call engineering_init(model, exc, opts, 0.0_dp, eng, err)
      call check(error, .not. allocated(err), 'engineering_init fails')
      if (allocated(error)) return
      u = [0.01_dp, 0.025_dp, 0.03_dp]
      v = [0.1_dp, -0.2_dp, 0.05_dp]
      f = [1.0e4_dp, 2.0e4_dp, 3.0e4_dp]
      call storey_values(eng, u, v, f, drift, shear, base)
      call check(error, all(abs(drift - [0.01_dp, 0.015_dp, 0.005_dp]) < 1.0e-15_dp), 'drifts')
      if (allocated(error)) return
      ! storey 2 (nodes 2, 1): spring k and spring k/2 reversed, device 1 along, device 2 reversed
      exp_shear(1) = k*(0.01_dp + a1*0.1_dp) + 3.0e4_dp
      exp_shear(2) = (k + k/2)*(0.015_dp + a1*(-0.3_dp)) + 1.0e4_dp - 2.0e4_dp
      exp_shear(3) = k*(0.005_dp + a1*0.25_dp)
      exp_base = exp_shear(1)
      call check_close(error, shear(1), exp_shear(1), 1.0e-14_dp, 'storey 1 shear')
      if (allocated(error)) return
      call check_close(error, shear(2), exp_shear(2), 1.0e-14_dp, 'storey 2 shear')
      if (allocated(error)) return
      call check_close(error, shear(3), exp_shear(3), 1.0e-14_dp, 'storey 3 shear')
      if (allocated(error)) return
      call check_close(error, base, exp_base, 1.0e-14_dp, 'base shear')
      if (allocated(error)) return
      ! peaks and the residual values (those of the last state observed)
      call observe_engineering(eng, 1.0_dp, 3, 3, u, v, f)
      call observe_engineering(eng, 2.0_dp, 3, 3, -2.0_dp*u, 0.0_dp*v, 0.0_dp*f)
      call observe_engineering(eng, 3.0_dp, 3, 3, 0.5_dp*u, 0.0_dp*v, 0.0_dp*f)
      call check(error, all(eng%peak_drift_time == 2.0_dp) .and. &
                 all(abs(eng%peak_drift - 2.0_dp*[0.01_dp, 0.015_dp, 0.005_dp]) < 1.0e-15_dp), 'peak drifts')
      if (allocated(error)) return
      call check(error, all(abs(eng%drift - 0.5_dp*[0.01_dp, 0.015_dp, 0.005_dp]) < 1.0e-15_dp), &
                 'residual drifts: the last state')
      if (allocated(error)) return
      call check_close(error, eng%peak_shear(0), 2.0_dp*k*0.01_dp, 1.0e-14_dp, 'peak base shear')
   end subroutine test_storeys

   !> The large-model path (natural_modes_sparse: fd_modes' subspace iteration on the
   !> elements, 100 DOFs so that it iterates) against the dense one (natural_modes), two
   !> independent eigensolvers: stuck (a rigid link, hysteretic sticking stiffness), free,
   !> and free without a spring to the table (a rigid-body mode, found through the shift);
   !> Rayleigh damping ratios from phi' K phi against phi' C phi.
   subroutine test_sparse_modes(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(modes_type) :: dense, sparse
      type(fd_error_type), allocatable :: err
      real(dp), allocatable :: kk(:, :), c(:, :), got(:)
      integer :: i, r, sys, case_, n

      n = 100
      do case_ = 1, 3
         ! devices: a velocity-law one at the base, hysteretic ones beside springs 2..6
         call chain(model, n, reshape([1, 0, (i, i - 1, i=2, 6)], [2, 6]), [law_velocity, (law_hysteretic, i=2, 6)])
         model%damping = damping_rayleigh
         model%rayleigh_a0 = 0.3_dp
         model%rayleigh_a1 = 2.0e-3_dp
         sys = merge(system_stuck, system_free, case_ == 1)
         if (case_ == 3) model%spring_k(1) = 0.0_dp   ! free: nothing holds the chain to the table
         if (allocated(kk)) deallocate (kk, c)
         allocate (kk(n, n), c(n, n))
         call stiffness_matrix(model, kk)
         call damping_matrix(model, kk, 0.0_dp, c)
         call natural_modes(model, kk, c, sys, 6, dense, err)
         call check(error, .not. allocated(err), 'natural_modes fails')
         if (allocated(error)) return
         call natural_modes_sparse(model, 0.3_dp, 2.0e-3_dp, sys, 6, sparse, err)
         call check(error, .not. allocated(err), 'natural_modes_sparse fails')
         if (allocated(error)) return
         call check(error, sparse%status == dense%status .and. sparse%nq == dense%nq .and. sparse%n == 6, &
                    'status and counts')
         if (allocated(error)) return
         call check(error, (case_ == 3) .eqv. (sparse%status == modes_unrestrained), 'a rigid-body mode when free')
         if (allocated(error)) return
         do r = 1, 6
            if (dense%omega2(r) == 0.0_dp) then
               call check(error, sparse%omega2(r) == 0.0_dp .and. .not. ieee_is_finite(sparse%period(r)), &
                          'the rigid-body mode')
               if (allocated(error)) return
               cycle
            end if
            call check_close(error, sparse%period(r), dense%period(r), 1.0e-8_dp, 'period')
            if (allocated(error)) return
            call check_close(error, sparse%xi(r), dense%xi(r), 1.0e-7_dp, 'modal damping ratio')
            if (allocated(error)) return
            call check_close(error, sparse%mass_ratio(r), dense%mass_ratio(r), 1.0e-6_dp, 'effective mass ratio', &
                             absolute=.true.)
            if (allocated(error)) return
            got = sparse%shape(:, r)*sign(1.0_dp, dot_product(sparse%shape(:, r), dense%shape(:, r)))
            call check_close(error, maxval(abs(got - dense%shape(:, r))), 0.0_dp, 1.0e-6_dp, 'shape', &
                             absolute=.true.)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_sparse_modes

   !> The absolute acceleration at the corners of a rigid floor 20 m x 12 m whose centre of
   !> mass accelerates by (a_x, a_y) and turns by a_rz (the table's r ag and r2 ag2 added):
   !> the largest over the four corners is |a_x| + |a_rz| 6 along x, |a_y| + |a_rz| 10 along y;
   !> a floor without a plan keeps none; a smaller state later leaves the peaks and times.
   subroutine test_corner_acc(error)
      type(error_type), allocatable, intent(out) :: error
      type(engineering_type) :: eng
      real(dp) :: acc(6)

      eng%n_floors = 2
      allocate (eng%half_plan(2, 2), eng%peak_corner_aabs(2, 2), eng%peak_corner_aabs_time(2, 2))
      eng%half_plan = reshape([6.0_dp, 10.0_dp, 0.0_dp, 0.0_dp], [2, 2])
      eng%peak_corner_aabs = 0.0_dp
      eng%peak_corner_aabs_time = 0.0_dp
      eng%r = [0.8_dp, 0.6_dp, 0.0_dp, 0.8_dp, 0.6_dp, 0.0_dp]
      eng%r2 = [-0.6_dp, 0.8_dp, 0.0_dp, -0.6_dp, 0.8_dp, 0.0_dp]
      acc = [1.0_dp, -2.0_dp, 0.3_dp, 5.0_dp, 5.0_dp, 1.0_dp]
      call observe_floor_accelerations(eng, 1.5_dp, 6, acc, 2.0_dp, -1.0_dp)
      ! a_x = 1 + 0.8 * 2 + 0.6 = 3.2, a_y = -2 + 1.2 - 0.8 = -1.6
      call check_close(error, eng%peak_corner_aabs(1, 1), 3.2_dp + 0.3_dp*6.0_dp, 1.0e-15_dp, "corner a_x")
      if (allocated(error)) return
      call check_close(error, eng%peak_corner_aabs(2, 1), 1.6_dp + 0.3_dp*10.0_dp, 1.0e-15_dp, "corner a_y")
      if (allocated(error)) return
      call check(error, all(eng%peak_corner_aabs(:, 2) == 0.0_dp), "a floor without a plan has no corners")
      if (allocated(error)) return
      call observe_floor_accelerations(eng, 2.0_dp, 6, 0.1_dp*acc, 0.0_dp, 0.0_dp)
      call check(error, all(eng%peak_corner_aabs_time(:, 1) == 1.5_dp), "the peak's time stays")
   end subroutine test_corner_acc

end module test_fd_engineering
