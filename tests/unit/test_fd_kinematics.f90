!> Device kinematics: directions from two nodes, relative motion, forces along a direction,
!> the mass a device moves and the coupling of two devices, for devices between two nodes
!> and along general directions (against the same quantities assembled densely).
module test_fd_kinematics
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use test_fd_helpers, only: check_close
   use fd_kinds, only: dp
   use fd_model, only: model_type, device_type
   use fd_kinematics, only: set_pair_directions, device_kinematics, device_relative, add_device, &
                            add_device_outer, moved_mass, device_coupling, device_inverse_mass_relative, &
                            pair_nodes, devices_are_pairs, device_nodes, relative_motion, device_forces
   implicit none
   private

   public :: collect_kinematics

contains

   subroutine collect_kinematics(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("directions of devices between two nodes", test_pairs), &
                  new_unittest("general directions against dense products", test_general), &
                  new_unittest("the time-step loops' kernels, pairs and general", test_loop_kernels) &
                  ]
   end subroutine collect_kinematics

   !> Three DOFs; devices 2-1, 3-table and 1-3.
   subroutine pair_model(model)
      type(model_type), intent(out) :: model
      integer :: stat

      model%n_dof = 3
      model%mass = [2.0_dp, 3.0_dp, 5.0_dp]
      model%n_devices = 3
      model%dev = [device_type(node_i=2, node_j=1), device_type(node_i=3, node_j=0), &
                   device_type(node_i=1, node_j=3)]
      call set_pair_directions(model, stat)
      if (stat /= 0) error stop "pair_model: no memory"
   end subroutine pair_model

   subroutine test_pairs(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      real(dp) :: u(3), v(3), s(3), sd(3), y(3)
      integer :: i, j, ni(3), nj(3), first

      call pair_model(model)
      call check(error, all(model%dev_ptr == [1, 3, 4, 6]), "three devices, five terms")
      if (allocated(error)) return
      u = [0.1_dp, 0.4_dp, -0.2_dp]
      v = [1.0_dp, -2.0_dp, 0.5_dp]
      call device_kinematics(model, u, v, s, sd)
      call check(error, all(s == [0.3_dp, -0.2_dp, 0.3_dp] .or. abs(s - [0.3_dp, -0.2_dp, 0.3_dp]) < 1.0e-15_dp), &
                 "s = u_i - u_j")
      if (allocated(error)) return
      call check(error, all(sd == [-3.0_dp, 0.5_dp, 0.5_dp]), "s' = v_i - v_j")
      if (allocated(error)) return
      y = 0.0_dp
      call add_device(model, 1, 7.0_dp, y)
      call add_device(model, 2, 1.0_dp, y)
      call check(error, all(y == [-7.0_dp, 7.0_dp, 1.0_dp]), "F b: +F on node_i, -F on node_j")
      if (allocated(error)) return
      call check_close(error, moved_mass(model, 1), 2.0_dp*3.0_dp/5.0_dp, 1.0e-15_dp, "m_i m_j / (m_i + m_j)")
      if (allocated(error)) return
      call check(error, moved_mass(model, 2) == 5.0_dp, "m_i to the table")
      if (allocated(error)) return
      ! devices 1 (2-1) and 3 (1-3) share node 1 with opposite signs: -1/m_1
      call check_close(error, device_coupling(model, 1, 3), -0.5_dp, 1.0e-15_dp, "b_1' M^-1 b_3")
      if (allocated(error)) return
      call pair_nodes(model, 3, i, j)
      call check(error, i == 1 .and. j == 3 .and. devices_are_pairs(model), "the nodes back")
      if (allocated(error)) return
      call device_nodes(model, ni, nj, first)
      call check(error, first == 0 .and. all(ni == [2, 3, 1]) .and. all(nj == [1, 0, 3]), "device_nodes")
   end subroutine test_pairs

   subroutine test_general(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      real(dp) :: bmat(4, 2), u(4), f(4), a(4, 4), expect(4, 4)
      integer :: i, j, ni(2), nj(2), first

      ! a brace at a plan point of a floor (ux, uy, rz: DOFs 1-3) against the table, and a
      ! device between DOF 4 and the floor's ux
      model%n_dof = 4
      model%mass = [2.0e4_dp, 2.0e4_dp, 3.0e5_dp, 1.0e3_dp]
      model%n_devices = 2
      allocate (model%dev(2))
      model%dev_ptr = [1, 4, 6]
      model%dev_dof = [1, 2, 3, 4, 1]
      model%dev_coef = [0.6_dp, 0.8_dp, 2.5_dp, 1.0_dp, -1.0_dp]
      bmat = 0.0_dp
      bmat(:, 1) = [0.6_dp, 0.8_dp, 2.5_dp, 0.0_dp]
      bmat(:, 2) = [-1.0_dp, 0.0_dp, 0.0_dp, 1.0_dp]
      u = [0.01_dp, -0.02_dp, 0.003_dp, 0.04_dp]
      call check_close(error, device_relative(model, 1, u), dot_product(bmat(:, 1), u), 1.0e-15_dp, "b' u")
      if (allocated(error)) return
      f = 0.0_dp
      call add_device(model, 1, 3.0_dp, f)
      call check(error, all(abs(f - 3.0_dp*bmat(:, 1)) <= 1.0e-15_dp), "F b")
      if (allocated(error)) return
      call check_close(error, device_inverse_mass_relative(model, 1, u), sum(bmat(:, 1)*u/model%mass), &
                       1.0e-15_dp, "b' M^-1 y")
      if (allocated(error)) return
      call check_close(error, device_coupling(model, 1, 2), sum(bmat(:, 1)*bmat(:, 2)/model%mass), 1.0e-15_dp, &
                       "b_1' M^-1 b_2")
      if (allocated(error)) return
      call check_close(error, moved_mass(model, 1), 1.0_dp/sum(bmat(:, 1)**2/model%mass), 1.0e-15_dp, &
                       "1 / (b' M^-1 b)")
      if (allocated(error)) return
      a = 0.0_dp
      call add_device_outer(model, 1, 2.0_dp, a)
      do j = 1, 4
         do i = 1, 4
            expect(i, j) = 2.0_dp*bmat(i, 1)*bmat(j, 1)
         end do
      end do
      call check(error, all(abs(a - expect) <= 1.0e-15_dp), "kd b b'")
      if (allocated(error)) return
      ! device 2 is between two nodes, device 1 is not
      call pair_nodes(model, 1, i, j)
      call check(error, i == 0 .and. j == 0, "a brace at a plan point is not a pair")
      if (allocated(error)) return
      call pair_nodes(model, 2, i, j)
      call check(error, i == 4 .and. j == 1, "e_4 - e_1 is the pair (4, 1)")
      if (allocated(error)) return
      call device_nodes(model, ni, nj, first)
      call check(error, first == 1 .and. .not. devices_are_pairs(model), "the first general device named")
   end subroutine test_general

   !> relative_motion and device_forces (the time-step loops' kernels) equal device_relative
   !> and add_device, by the nodes of a model of pairs and by the terms of a general one.
   subroutine test_loop_kernels(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      real(dp) :: u(4), v(4), y(4), z(4)
      real(dp), allocatable :: s(:), sd(:), f(:)
      integer :: d, pass

      u = [0.1_dp, 0.4_dp, -0.2_dp, 0.7_dp]
      v = [1.0_dp, -2.0_dp, 0.5_dp, 0.25_dp]
      do pass = 1, 2
         if (pass == 1) then
            call pair_model(model)
            call check(error, allocated(model%dev_nodes), "a model of pairs has its nodes")
         else
            model%n_dof = 4
            model%mass = [2.0e4_dp, 2.0e4_dp, 3.0e5_dp, 1.0e3_dp]
            model%n_devices = 2
            if (allocated(model%dev_nodes)) deallocate (model%dev_nodes)
            model%dev_ptr = [1, 4, 6]
            model%dev_dof = [1, 2, 3, 4, 1]
            model%dev_coef = [0.6_dp, 0.8_dp, 2.5_dp, 1.0_dp, -1.0_dp]
         end if
         if (allocated(error)) return
         allocate (s(model%n_devices), sd(model%n_devices), f(model%n_devices))
         call relative_motion(model, model%n_dof, model%n_devices, u(1:model%n_dof), v(1:model%n_dof), s, sd)
         f = [(1.5_dp*d, d=1, model%n_devices)]
         y = 0.25_dp
         z = 0.25_dp
         call device_forces(model, model%n_dof, model%n_devices, f, y(1:model%n_dof))
         do d = 1, model%n_devices
            call check(error, s(d) == device_relative(model, d, u(1:model%n_dof)) .and. &
                       sd(d) == device_relative(model, d, v(1:model%n_dof)), "s, s' as device_relative")
            if (allocated(error)) return
            call add_device(model, d, f(d), z(1:model%n_dof))
         end do
         call check(error, all(y == z), "forces as add_device")
         if (allocated(error)) return
         deallocate (s, sd, f)
      end do
   end subroutine test_loop_kernels

end module test_fd_kinematics
