!> Unit tests of the system matrices (fd_matrices): groups of DOFs joined by rigid links,
!> the stiffness and damping matrices, and the stuck system's first mode against closed forms.
module test_fd_matrices
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_model, only: model_type, device_type, damping_stiffness, damping_rayleigh, law_velocity, law_hysteretic, &
                       system_stuck, system_free
   use fd_matrices, only: link_groups, stiffness_matrix, damping_matrix, stuck_first_mode, structure_matrices, &
                          stiffness_pivot, system_modes, natural_modes, natural_modes_sparse, modes_type
   use fd_stiffness, only: stiffness_times, stiffness_form
   use fd_modes, only: modes_dense, modes_iterative
   use fd_kinematics, only: append_device
   use test_fd_helpers, only: check_close, check_matrix, pairs_of
   implicit none
   private

   public :: collect_matrices

   real(dp), parameter :: pi = acos(-1.0_dp)
   ! the paper's two-mass model (Dimova, "Experimental Facility")
   real(dp), parameter :: m1 = 6.301_dp, m2 = 2.530_dp, k1 = 1084.0_dp, k2 = 2895.0_dp

contains

   subroutine collect_matrices(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("link groups", test_link_groups), &
                  new_unittest("link groups through the table", test_link_groups_table), &
                  new_unittest("stiffness matrix", test_stiffness), &
                  new_unittest("K u and x' K y without the matrix", test_stiffness_products), &
                  new_unittest("damping matrices", test_damping), &
                  new_unittest("stuck mode, device between the masses", test_stuck_linked), &
                  new_unittest("stuck mode, no friction capacity", test_stuck_free), &
                  new_unittest("stuck mode, everything locked", test_stuck_locked), &
                  new_unittest("damping ratio of the stuck mode", test_structure_xi), &
                  new_unittest("stiffness pivot: mechanisms and indefinite K", test_stiffness_pivot), &
                  new_unittest("stiffness pivot in the RCM ordering", test_stiffness_pivot_rcm), &
                  new_unittest("general modes: banded against dense", test_general_system_modes), &
                  new_unittest("general natural modes: banded against dense", test_general_natural_modes) &
                  ]
   end subroutine collect_matrices

   !> A model of n masses with the given springs (node_i, node_j, k) and devices (node_i, node_j).
   subroutine make_model(model, mass, springs, devices)
      type(model_type), intent(out) :: model
      real(dp), intent(in) :: mass(:)
      real(dp), intent(in) :: springs(:, :)   !! (3, n_springs): node_i, node_j, k
      integer, intent(in) :: devices(:, :)    !! (2, n_devices): node_i, node_j
      integer :: d

      model%n_dof = size(mass)
      model%mass = mass
      model%u0 = 0.0_dp*mass
      model%v0 = 0.0_dp*mass
      model%n_springs = size(springs, 2)
      model%spring_i = nint(springs(1, :))
      model%spring_j = nint(springs(2, :))
      model%spring_k = springs(3, :)
      model%n_devices = size(devices, 2)
      allocate (model%dev(model%n_devices))
      do d = 1, model%n_devices
         model%dev(d)%node_i = devices(1, d)
         model%dev(d)%node_j = devices(2, d)
         model%dev(d)%law = law_velocity
         model%dev(d)%p = 10.0_dp
         model%dev(d)%mu = 0.2_dp
      end do
      call pairs_of(model)
   end subroutine make_model

   !> The paper's model: m1 on k1 and m2 on k2 to the table, one device between them.
   subroutine paper_model(model)
      type(model_type), intent(out) :: model
      call make_model(model, [m1, m2], reshape([1.0_dp, 0.0_dp, k1, 2.0_dp, 0.0_dp, k2], [3, 2]), &
                      reshape([1, 2], [2, 1]))
   end subroutine paper_model

   !> Five DOFs; links 1-2, 4-5 and 5-4 (repeated), 3 unlinked: groups {1, 2}, {3}, {4, 5},
   !> numbered in the order of their first DOF.
   subroutine test_link_groups(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      integer :: grp(5), nq
      real(dp) :: no_springs(3, 0)

      call make_model(model, [1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp], no_springs, &
                      reshape([2, 1, 3, 2, 4, 5, 5, 4], [2, 4]))
      call link_groups(model, [.true., .false., .true., .true.], grp, nq)
      call check(error, nq, 3, 'three moving groups')
      if (allocated(error)) return
      call check(error, all(grp == [1, 1, 2, 3, 3]), 'groups {1, 2}, {3}, {4, 5}')
      if (allocated(error)) return
      ! the unlinked device 3-2 linked too: {1, 2, 3}, {4, 5}
      call link_groups(model, [.true., .true., .true., .true.], grp, nq)
      call check(error, nq, 2, 'two moving groups')
      if (allocated(error)) return
      call check(error, all(grp == [1, 1, 1, 2, 2]), 'groups {1, 2, 3}, {4, 5}')
      if (allocated(error)) return
      ! nothing linked: every DOF its own group
      call link_groups(model, [.false., .false., .false., .false.], grp, nq)
      call check(error, nq == 5 .and. all(grp == [1, 2, 3, 4, 5]), 'no links: five groups')
   end subroutine test_link_groups

   !> A chain of links that reaches the table (0-3, 3-1, 1-4) puts 1, 3 and 4 with the table.
   subroutine test_link_groups_table(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      integer :: grp(4), nq
      real(dp) :: no_springs(3, 0)

      call make_model(model, [1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp], no_springs, reshape([1, 4, 3, 1, 3, 0], [2, 3]))
      call link_groups(model, [.true., .true., .true.], grp, nq)
      call check(error, nq, 1, 'one moving group')
      if (allocated(error)) return
      call check(error, all(grp == [0, 1, 0, 0]), 'DOFs 1, 3, 4 with the table')
      if (allocated(error)) return
      ! without the link to the table, {1, 3, 4} moves
      call link_groups(model, [.true., .true., .false.], grp, nq)
      call check(error, nq == 2 .and. all(grp == [1, 2, 1, 1]), 'groups {1, 3, 4}, {2}')
   end subroutine test_link_groups_table

   !> A chain table - 1 - 2 - 3 with k = 100, 20, 3, and a spring 3 - 1 of 0.5.
   subroutine test_stiffness(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      real(dp) :: k(3, 3), expected(3, 3)
      integer :: no_devices(2, 0)

      call make_model(model, [1.0_dp, 1.0_dp, 1.0_dp], reshape([1.0_dp, 0.0_dp, 100.0_dp, 2.0_dp, 1.0_dp, 20.0_dp, &
                      3.0_dp, 2.0_dp, 3.0_dp, 3.0_dp, 1.0_dp, 0.5_dp], [3, 4]), no_devices)
      call stiffness_matrix(model, k)
      expected = reshape([120.5_dp, -20.0_dp, -0.5_dp, -20.0_dp, 23.0_dp, -3.0_dp, -0.5_dp, -3.0_dp, 3.5_dp], [3, 3])
      call check_matrix(error, k, expected, 0.0_dp, 'stiffness of a chain with a cross spring (exact)')
   end subroutine test_stiffness

   !> K u and x' K y of the chain with a cross spring above, and K_x's entries (1, 3) and
   !> (2, 2) added: the stiffness matrix's products, exact in binary (small integers).
   subroutine test_stiffness_products(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      real(dp) :: k(3, 3), ku(3)
      real(dp), parameter :: u(3) = [1.0_dp, -2.0_dp, 4.0_dp], y(3) = [3.0_dp, 0.5_dp, -1.0_dp]
      integer :: no_devices(2, 0)

      call make_model(model, [1.0_dp, 1.0_dp, 1.0_dp], reshape([1.0_dp, 0.0_dp, 100.0_dp, 2.0_dp, 1.0_dp, 20.0_dp, &
                      3.0_dp, 2.0_dp, 3.0_dp, 3.0_dp, 1.0_dp, 0.5_dp], [3, 4]), no_devices)
      model%n_kx = 2
      model%kx_i = [1, 2]
      model%kx_j = [3, 2]
      model%kx_v = [-2.0_dp, 7.0_dp]
      call stiffness_matrix(model, k)
      call stiffness_times(model, u, ku)
      call check(error, all(ku == matmul(k, u)), 'K u')
      if (allocated(error)) return
      call check(error, stiffness_form(model, u, y), dot_product(u, matmul(k, y)), "x' K y")
      if (allocated(error)) return
      call check(error, stiffness_form(model, u, y), stiffness_form(model, y, u), "x' K y = y' K x")
   end subroutine test_stiffness_products

   !> K positive definite or not, by the banded factor in the DOFs' own ordering (a chain has
   !> band 1 either way): a grounded chain passes; the free chain 1 - 2 - 3 (pivots k, k/2...
   !> exactly 0 at the last) fails at DOF 3; k 0.1, 0.3 free fails at DOF 3 by round-off or
   !> zero alike; K_x with a negative diagonal at DOF 2 fails there.
   subroutine test_stiffness_pivot(error)
      type(error_type), allocatable, intent(out) :: error
      type(fd_error_type), allocatable :: ferr
      type(model_type) :: model
      integer :: no_devices(2, 0), dof

      call make_model(model, [1.0_dp, 1.0_dp, 1.0_dp], reshape([1.0_dp, 0.0_dp, 100.0_dp, 2.0_dp, 1.0_dp, 20.0_dp, &
                      3.0_dp, 2.0_dp, 3.0_dp], [3, 3]), no_devices)
      call stiffness_pivot(model, dof, ferr)
      call check(error, .not. allocated(ferr) .and. dof == 0, 'a grounded chain is positive definite')
      if (allocated(error)) return
      call make_model(model, [1.0_dp, 1.0_dp, 1.0_dp], reshape([2.0_dp, 1.0_dp, 20.0_dp, 3.0_dp, 2.0_dp, 20.0_dp], &
                      [3, 2]), no_devices)
      call stiffness_pivot(model, dof, ferr)
      call check(error, dof, 3, 'a free chain fails at its last DOF')
      if (allocated(error)) return
      call make_model(model, [1.0_dp, 1.0_dp, 1.0_dp], reshape([1.0_dp, 2.0_dp, 0.1_dp, 2.0_dp, 3.0_dp, 0.3_dp], &
                      [3, 2]), no_devices)
      call stiffness_pivot(model, dof, ferr)
      call check(error, dof, 3, 'a free chain of 0.1 and 0.3: its last pivot zero to working precision')
      if (allocated(error)) return
      ! the grounded chain with K_x: 5 at (1, 1), -30 at (2, 2) (K(2, 2) = 23 - 30 < 0)
      call make_model(model, [1.0_dp, 1.0_dp, 1.0_dp], reshape([1.0_dp, 0.0_dp, 100.0_dp, 2.0_dp, 1.0_dp, 20.0_dp, &
                      3.0_dp, 2.0_dp, 3.0_dp], [3, 3]), no_devices)
      model%n_kx = 2
      model%kx_i = [1, 2]
      model%kx_j = [1, 2]
      model%kx_v = [5.0_dp, -30.0_dp]
      call stiffness_pivot(model, dof, ferr)
      call check(error, dof, 2, 'K_x making K(2, 2) negative fails at DOF 2')
   end subroutine test_stiffness_pivot

   !> Two chains numbered across each other (springs 1-6, 6-2 and 1 to the table; 5-3, 3-4
   !> free): band 5 in the DOFs' ordering, 1 in reverse Cuthill-McKee's, which the check
   !> takes; the DOF it names is one of the free chain's, in the model's numbering. With 4
   !> on the table too, positive definite.
   subroutine test_stiffness_pivot_rcm(error)
      type(error_type), allocatable, intent(out) :: error
      type(fd_error_type), allocatable :: ferr
      type(model_type) :: model
      integer :: no_devices(2, 0), dof

      call make_model(model, [1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp, 1.0_dp], reshape([1.0_dp, 0.0_dp, 7.0_dp, &
                      1.0_dp, 6.0_dp, 3.0_dp, 6.0_dp, 2.0_dp, 5.0_dp, 5.0_dp, 3.0_dp, 2.0_dp, 3.0_dp, 4.0_dp, 4.0_dp], &
                      [3, 5]), no_devices)
      call stiffness_pivot(model, dof, ferr)
      call check(error, any(dof == [3, 4, 5]), 'the free chain {5, 3, 4} named (DOF '//char(48 + dof)//')')
      if (allocated(error)) return
      model%n_kx = 1
      model%kx_i = [4]
      model%kx_j = [4]
      model%kx_v = [1.0_dp]
      call stiffness_pivot(model, dof, ferr)
      call check(error, .not. allocated(ferr) .and. dof == 0, 'both chains grounded: positive definite')
   end subroutine test_stiffness_pivot_rcm

   !> A general model of 60 DOFs: springs of a chain to the table, K_x coupling each DOF to
   !> the third after it (diagonally dominant: 40 on the diagonal, -10 to -14 off it), masses
   !> 1 to 3; devices 5-20, 20-40 and 5-40
   !> (velocity law: three links of rank two), 50 to the table, and a hysteretic device of
   !> direction (1, -0.5, 0.25) on DOFs 10, 30, 59 (its sticking spring 400).
   subroutine general_model(model)
      type(model_type), intent(out) :: model
      type(device_type) :: dev
      real(dp) :: springs(3, 60), mass(60)
      integer :: i, stat

      do i = 1, 60
         mass(i) = 1.0_dp + 2.0_dp*real(mod(7*i, 11), dp)/10.0_dp
         springs(:, i) = [real(i, dp), real(i - 1, dp), 100.0_dp + real(mod(3*i, 7), dp)*20.0_dp]
      end do
      call make_model(model, mass, springs, reshape([5, 20, 20, 40, 5, 40, 50, 0], [2, 4]))
      model%n_kx = 60 + 57
      allocate (model%kx_i(model%n_kx), model%kx_j(model%n_kx), model%kx_v(model%n_kx))
      do i = 1, 60
         model%kx_i(i) = i
         model%kx_j(i) = i
         model%kx_v(i) = 40.0_dp
      end do
      do i = 1, 57
         model%kx_i(60 + i) = i
         model%kx_j(60 + i) = i + 3
         model%kx_v(60 + i) = -10.0_dp - real(mod(i, 5), dp)
      end do
      dev%law = law_hysteretic
      dev%p = 4.0_dp
      dev%mu = 1.0_dp
      dev%f = 0.01_dp
      call append_device(model, dev, [10, 30, 59], [1.0_dp, -0.5_dp, 0.25_dp], stat)
      if (stat /= 0) error stop "general_model: not enough memory"
   end subroutine general_model

   !> The modes of a general model with the links as constraints (system_modes): the banded
   !> path (subspace iteration on the null space through the constraints' Schur complement)
   !> against the dense one (the null space's basis, dsygv), eigenvalues to 1e-10 relative
   !> and M-normalized shapes to 1e-8; the null space has 60 - 3 free DOFs (the three links
   !> 5-20-40-5 constrain two).
   subroutine test_general_system_modes(error)
      type(error_type), allocatable, intent(out) :: error
      type(fd_error_type), allocatable :: ferr
      type(model_type) :: model
      real(dp) :: w_dense(6), w_band(6), z_dense(60, 6), z_band(60, 6), s
      integer :: nq_dense, nq_band, j
      logical :: linked(5)

      call general_model(model)
      linked = [.true., .true., .true., .true., .false.]
      call system_modes(model, linked, 6, w_dense, z_dense, nq_dense, ferr, modes_dense)
      call check(error, .not. allocated(ferr), 'dense modes'//message_of(ferr))
      if (allocated(error)) return
      call system_modes(model, linked, 6, w_band, z_band, nq_band, ferr, modes_iterative)
      call check(error, .not. allocated(ferr), 'banded modes'//message_of(ferr))
      if (allocated(error)) return
      call check(error, nq_dense, 57, 'dense: 60 DOFs less the rank 3 of four links')
      if (allocated(error)) return
      call check(error, nq_band, 57, 'banded: 60 DOFs less the rank 3 of four links')
      if (allocated(error)) return
      call check_each(error, w_band, w_dense, 1.0e-10_dp, 'eigenvalues')
      if (allocated(error)) return
      do j = 1, 6
         s = sign(1.0_dp, sum(model%mass*z_band(:, j)*z_dense(:, j)))
         call check_each(error, s*z_band(:, j), z_dense(:, j), 1.0e-8_dp, 'mode shape', absolute=.true.)
         if (allocated(error)) return
      end do
      ! the banded shapes satisfy the links: u_5 = u_20 = u_40, u_50 = 0
      call check(error, maxval(abs([z_band(5, :) - z_band(20, :), z_band(20, :) - z_band(40, :), z_band(50, :)])) &
                 < 1.0e-12_dp*maxval(abs(z_band)), 'the links hold in the banded shapes')
   end subroutine test_general_system_modes

   !> natural_modes_sparse of a general model (banded: the hysteretic device's sticking spring
   !> in K, the linking devices as constraints) against natural_modes (dense matrices), stuck
   !> and free: periods, damping ratios (Rayleigh) and mass ratios to 1e-10, shapes to 1e-8.
   subroutine test_general_natural_modes(error)
      type(error_type), allocatable, intent(out) :: error
      type(fd_error_type), allocatable :: ferr
      type(model_type) :: model
      type(modes_type) :: dense, band
      real(dp) :: k(60, 60), c(60, 60)
      real(dp), parameter :: a0 = 0.3_dp, a1 = 2.0e-3_dp
      integer :: system, i, is

      call general_model(model)
      call stiffness_matrix(model, k)
      c = a1*k
      do i = 1, 60
         c(i, i) = c(i, i) + a0*model%mass(i)
      end do
      do is = 1, 2
         system = merge(system_stuck, system_free, is == 1)
         call natural_modes(model, k, c, system, 5, dense, ferr)
         call check(error, .not. allocated(ferr), 'dense natural modes'//message_of(ferr))
         if (allocated(error)) return
         call natural_modes_sparse(model, a0, a1, system, 5, band, ferr)
         call check(error, .not. allocated(ferr), 'banded natural modes'//message_of(ferr))
         if (allocated(error)) return
         call check(error, band%nq, dense%nq, 'free DOFs')
         if (allocated(error)) return
         call check(error, band%status, dense%status, 'status')
         if (allocated(error)) return
         call check_each(error, band%period, dense%period, 1.0e-10_dp, 'periods')
         if (allocated(error)) return
         call check_each(error, band%xi, dense%xi, 1.0e-10_dp, 'damping ratios')
         if (allocated(error)) return
         call check_each(error, band%mass_ratio, dense%mass_ratio, 1.0e-10_dp, 'mass ratios', absolute=.true.)
         if (allocated(error)) return
         call check_each(error, reshape(band%shape, [300]), reshape(dense%shape, [300]), 1.0e-8_dp, 'shapes', &
                          absolute=.true.)
         if (allocated(error)) return
      end do
   end subroutine test_general_natural_modes

   !> ": " and an error's message, or nothing.
   function message_of(ferr) result(text)
      type(fd_error_type), allocatable, intent(in) :: ferr
      character(len=200) :: text
      text = ''
      if (allocated(ferr)) text = ': '//ferr%message
   end function message_of

   !> check_close of each element of two arrays of one size.
   subroutine check_each(error, actual, expected, tol, what, absolute)
      type(error_type), allocatable, intent(out) :: error
      real(dp), intent(in) :: actual(:), expected(:), tol
      character(len=*), intent(in) :: what
      logical, intent(in), optional :: absolute
      integer :: i

      call check(error, size(actual), size(expected), what//': sizes')
      do i = 1, size(expected)
         if (allocated(error)) return
         call check_close(error, actual(i), expected(i), tol, what, absolute)
      end do
   end subroutine check_each

   !> C = (T xi / pi) K for 'stiffness'; C = a0 M + a1 K for 'rayleigh'.
   subroutine test_damping(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      real(dp) :: k(2, 2), c(2, 2), expected(2, 2)

      call paper_model(model)
      call stiffness_matrix(model, k)
      model%damping = damping_stiffness
      model%xi = 0.015_dp
      call damping_matrix(model, k, 0.3_dp, c)
      call check_matrix(error, c, (0.3_dp*0.015_dp/pi)*k, 1.0e-15_dp, 'stiffness-proportional damping')
      if (allocated(error)) return
      model%damping = damping_rayleigh
      model%rayleigh_a0 = 0.4_dp
      model%rayleigh_a1 = 0.002_dp
      call damping_matrix(model, k, 0.0_dp, c)
      expected = 0.002_dp*k
      expected(1, 1) = expected(1, 1) + 0.4_dp*m1
      expected(2, 2) = expected(2, 2) + 0.4_dp*m2
      call check_matrix(error, c, expected, 1.0e-15_dp, 'Rayleigh damping')
   end subroutine test_damping

   !> The device between the masses is a rigid link: one body m1 + m2 on k1 + k2,
   !> T = 2 pi sqrt((m1 + m2)/(k1 + k2)) (the paper's 0.296 s), both masses moving alike.
   subroutine test_stuck_linked(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      real(dp) :: period, phi(2)
      type(fd_error_type), allocatable :: err

      call paper_model(model)
      call stuck_first_mode(model, period, phi, err)
      call check(error, .not. allocated(err), 'stuck_first_mode failed')
      if (allocated(error)) return
      call check_close(error, period, 2.0_dp*pi*sqrt((m1 + m2)/(k1 + k2)), 1.0e-14_dp, 'T of the rigid two-mass body')
      if (allocated(error)) return
      call check(error, phi(1) == phi(2) .and. phi(1) /= 0.0_dp, 'the linked masses share one mode value')
      if (allocated(error)) return
      call check_close(error, (m1 + m2)*phi(1)**2, 1.0_dp, 1.0e-14_dp, 'the mode is mass-normalized')
   end subroutine test_stuck_linked

   !> With P mu = 0 the device links nothing: two oscillators, the slower one first
   !> (sqrt(k1/m1) = 13.1 rad/s < sqrt(k2/m2) = 33.8 rad/s); its mode moves m1 only.
   !> A 2-DOF chain (table - m - m, k, k) with no device: w^2 = (k/m)(3 - sqrt(5))/2.
   subroutine test_stuck_free(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      real(dp) :: period, phi(2)
      type(fd_error_type), allocatable :: err
      integer :: no_devices(2, 0)

      call paper_model(model)
      model%dev(1)%p = 0.0_dp
      call stuck_first_mode(model, period, phi, err)
      call check(error, .not. allocated(err), 'stuck_first_mode failed')
      if (allocated(error)) return
      call check_close(error, period, 2.0_dp*pi*sqrt(m1/k1), 1.0e-14_dp, 'T of the slower free oscillator')
      if (allocated(error)) return
      call check(error, phi(2) == 0.0_dp, 'the first mode moves m1 only')
      if (allocated(error)) return
      call make_model(model, [2.0_dp, 2.0_dp], reshape([1.0_dp, 0.0_dp, 800.0_dp, 2.0_dp, 1.0_dp, 800.0_dp], [3, 2]), &
                      no_devices)
      call stuck_first_mode(model, period, phi, err)
      call check_close(error, period, 2.0_dp*pi/sqrt(400.0_dp*(3.0_dp - sqrt(5.0_dp))/2.0_dp), 1.0e-14_dp, &
                       'T of a two-mass chain')
   end subroutine test_stuck_free

   !> Every mass locked to the table: no free DOF, an error (not a zero period); a free mass
   !> with no spring: a rigid-body mode, an error.
   subroutine test_stuck_locked(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      real(dp) :: period, phi(2)
      type(fd_error_type), allocatable :: err

      call make_model(model, [m1, m2], reshape([1.0_dp, 0.0_dp, k1, 2.0_dp, 0.0_dp, k2], [3, 2]), &
                      reshape([1, 0, 2, 1], [2, 2]))
      call stuck_first_mode(model, period, phi, err)
      call check(error, allocated(err), 'all locked: an error')
      if (allocated(error)) return
      call check(error, index(err%message, 'no free DOF') > 0, err%message)
      if (allocated(error)) return
      call make_model(model, [m1, m2], reshape([1.0_dp, 0.0_dp, k1], [3, 1]), reshape([1, 2], [2, 1]))
      model%dev(1)%p = 0.0_dp
      call stuck_first_mode(model, period, phi, err)
      call check(error, allocated(err), 'a mass without a spring: an error')
      if (allocated(error)) return
      call check(error, index(err%message, 'rigid-body mode') > 0, err%message)
   end subroutine test_stuck_locked

   !> With C = (T xi / pi) K the stuck first mode's damping ratio is xi exactly:
   !> phi' C phi / (2 w phi' M phi) = (T xi / pi) w^2 / (2 w) = xi.
   subroutine test_structure_xi(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      real(dp) :: k(2, 2), c(2, 2), period, xi
      type(fd_error_type), allocatable :: err

      call paper_model(model)
      model%damping = damping_stiffness
      model%xi = 0.015_dp
      call structure_matrices(model, k, c, period, xi, err)
      call check(error, .not. allocated(err), 'structure_matrices failed')
      if (allocated(error)) return
      call check_close(error, xi, 0.015_dp, 1.0e-14_dp, 'damping ratio of the stuck mode')
      if (allocated(error)) return
      call check_matrix(error, c, (period*0.015_dp/pi)*k, 1.0e-15_dp, 'C = psi K with psi = T xi / pi')
   end subroutine test_structure_xi

end module test_fd_matrices
