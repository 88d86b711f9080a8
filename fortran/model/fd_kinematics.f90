!> Kinematics of the friction devices: the one place that knows a device's geometry. Device
!> d has a direction b_d over the DOFs (sparse: a few terms, kept in the model as dev_ptr,
!> dev_dof, dev_coef); its relative displacement is s_d = b_d' u and its force F_d enters the
!> equations of motion as b_d F_d. A device between two nodes has b_d = e_i - e_j (node 0,
!> the table, dropped). Every technique and check reaches a device's motion through the
!> routines here; those that group nodes joined by stuck devices (the exact technique's
!> phase patterns, Moreau-Jean's sticking groups, the stuck system's modes) ask device_pair
!> for the two nodes, and refuse a model whose devices are not all between two nodes.
module fd_kinematics
   use fd_kinds, only: dp
   use fd_model, only: model_type, device_type
   implicit none
   private

   public :: set_pair_directions, pair_terms, append_device
   public :: device_kinematics, device_relative, device_abs_relative, add_device
   public :: relative_motion, device_forces
   public :: add_device_abs, add_device_outer, pair_nodes, device_nodes, devices_are_pairs, moved_mass
   public :: device_inverse_mass_relative, device_abs_inverse_mass_relative, device_coupling

contains

   !> The directions of devices between two nodes: b_d = e_i - e_j (e_i when node_j = 0)
   !> from each device's node_i and node_j. stat /= 0: not enough memory.
   pure subroutine set_pair_directions(model, stat)
      type(model_type), intent(inout) :: model  !! the model; its devices' nodes are read
      integer, intent(out) :: stat              !! 0, or the allocation's status

      integer :: nd, d

      nd = model%n_devices
      if (allocated(model%dev_ptr)) deallocate (model%dev_ptr)
      if (allocated(model%dev_dof)) deallocate (model%dev_dof)
      if (allocated(model%dev_coef)) deallocate (model%dev_coef)
      if (allocated(model%dev_nodes)) deallocate (model%dev_nodes)
      allocate (model%dev_ptr(nd + 1), model%dev_dof(2*nd), model%dev_coef(2*nd), model%dev_nodes(2, nd), &
                stat=stat)
      if (stat /= 0) return
      ! the nodes copied by device first: a component of an array of derived type passed as
      ! an argument would be copied to a temporary at the call
      do d = 1, nd
         model%dev_nodes(1, d) = model%dev(d)%node_i
         model%dev_nodes(2, d) = model%dev(d)%node_j
      end do
      call pair_terms(model%dev_nodes(1, :), model%dev_nodes(2, :), model%dev_ptr, model%dev_dof, &
                      model%dev_coef)
   end subroutine set_pair_directions

   !> Device `dev` appended to the model with the direction b of terms (dof, coef), after
   !> the devices whose directions are set (set_pair_directions first). The model's devices
   !> are then no longer all pairs when b is not one. stat /= 0: not enough memory.
   pure subroutine append_device(model, dev, dof, coef, stat)
      type(model_type), intent(inout) :: model  !! the model
      type(device_type), intent(in) :: dev      !! the device (node_i = node_j = 0)
      integer, intent(in) :: dof(:)             !! DOFs of b's terms (distinct, 1..n_dof)
      real(dp), intent(in) :: coef(:)           !! their coefficients (not 0)
      integer, intent(out) :: stat              !! 0, or the allocation's status
      integer :: nd, nt

      nd = model%n_devices
      nt = model%dev_ptr(nd + 1) - 1
      model%dev = [model%dev(1:nd), dev]
      model%dev_dof = [model%dev_dof(1:nt), dof]
      model%dev_coef = [model%dev_coef(1:nt), coef]
      model%dev_ptr = [model%dev_ptr(1:nd + 1), nt + size(dof) + 1]
      model%n_devices = nd + 1
      if (allocated(model%dev_nodes)) deallocate (model%dev_nodes)
      stat = 0
   end subroutine append_device

   !> The compressed directions of two-node elements: e_i - e_j, e_i when j = 0 (and -e_j
   !> when i = 0). ptr has size(ni) + 1 entries, dof and coef at least 2 size(ni).
   pure subroutine pair_terms(ni, nj, ptr, dof, coef)
      integer, intent(in) :: ni(:)            !! first node of each element (0..n)
      integer, intent(in) :: nj(:)            !! second node (0..n)
      integer, intent(out) :: ptr(:)          !! start of each element's terms
      integer, intent(out) :: dof(:)          !! DOF of each term
      real(dp), intent(out) :: coef(:)        !! coefficient of each term
      integer :: e, k

      k = 1
      do e = 1, size(ni)
         ptr(e) = k
         if (ni(e) > 0) then
            dof(k) = ni(e); coef(k) = 1.0_dp; k = k + 1
         end if
         if (nj(e) > 0) then
            dof(k) = nj(e); coef(k) = -1.0_dp; k = k + 1
         end if
      end do
      ptr(size(ni) + 1) = k
      dof(k:) = 0
      coef(k:) = 0.0_dp
   end subroutine pair_terms

   !> Relative displacement and velocity of every device, s = b' u and s' = b' v.
   pure subroutine device_kinematics(model, u, v, s, sd)
      type(model_type), intent(in) :: model   !! the model
      real(dp), intent(in), contiguous :: u(:)   !! displacements of the DOFs [m]
      real(dp), intent(in), contiguous :: v(:)   !! velocities of the DOFs [m/s]
      real(dp), intent(out), contiguous :: s(:)  !! relative displacement of each device [m]
      real(dp), intent(out), contiguous :: sd(:) !! relative velocity of each device [m/s]

      call relative_kernel(model%n_devices, model%dev_ptr, model%dev_dof, model%dev_coef, u, v, s, sd)
   end subroutine device_kinematics

   !> s = b' u and s' = b' v of every device, for a time-step loop: explicit shapes (no
   !> array descriptor is made per call, which for a model of one device costs as much as
   !> the sums). (Newmark's step takes devices that all join two nodes by their nodes.)
   pure subroutine relative_motion(model, n, nd, u, v, s, sd)
      type(model_type), intent(in) :: model   !! the model
      integer, intent(in) :: n, nd            !! DOFs and devices
      real(dp), intent(in) :: u(n), v(n)      !! displacements [m] and velocities [m/s]
      real(dp), intent(out) :: s(nd), sd(nd)  !! relative displacements and velocities

      call relative_kernel(nd, model%dev_ptr, model%dev_dof, model%dev_coef, u, v, s, sd)
   end subroutine relative_motion

   !> y = y + sum_d f_d b_d, for a time-step loop (as relative_motion).
   pure subroutine device_forces(model, n, nd, f, y)
      type(model_type), intent(in) :: model   !! the model
      integer, intent(in) :: n, nd            !! DOFs and devices
      real(dp), intent(in) :: f(nd)           !! force of each device [N]
      real(dp), intent(inout) :: y(n)         !! vector over the DOFs

      call force_kernel(nd, model%dev_ptr, model%dev_dof, model%dev_coef, f, y)
   end subroutine device_forces

   !> device_kinematics' loop on plain arrays; each sum starts from the first term.
   pure subroutine relative_kernel(nd, ptr, dof, coef, u, v, s, sd)
      integer, intent(in) :: nd, ptr(nd + 1), dof(*)
      real(dp), intent(in) :: coef(*), u(*), v(*)
      real(dp), intent(out) :: s(nd), sd(nd)
      real(dp) :: a, b
      integer :: d, k, k0

      do d = 1, nd
         k0 = ptr(d)
         a = 0.0_dp
         b = 0.0_dp
         if (ptr(d + 1) > k0) then
            a = coef(k0)*u(dof(k0))
            b = coef(k0)*v(dof(k0))
         end if
         do k = k0 + 1, ptr(d + 1) - 1
            a = a + coef(k)*u(dof(k))
            b = b + coef(k)*v(dof(k))
         end do
         s(d) = a
         sd(d) = b
      end do
   end subroutine relative_kernel

   !> device_forces' loop over the terms, on plain arrays.
   pure subroutine force_kernel(nd, ptr, dof, coef, f, y)
      integer, intent(in) :: nd, ptr(nd + 1), dof(*)
      real(dp), intent(in) :: coef(*), f(nd)
      real(dp), intent(inout) :: y(*)
      integer :: d, k

      do d = 1, nd
         do k = ptr(d), ptr(d + 1) - 1
            y(dof(k)) = y(dof(k)) + f(d)*coef(k)
         end do
      end do
   end subroutine force_kernel

   !> b_d' y: the relative value across device d of a vector over the DOFs.
   pure real(dp) function device_relative(model, d, y) result(rel)
      type(model_type), intent(in) :: model   !! the model
      integer, intent(in) :: d                !! device
      real(dp), intent(in) :: y(:)            !! displacements, velocities, ... of the DOFs
      integer :: k, k0

      ! the sum starts from the first term, not from 0, so that e_i' y is y_i to its sign
      k0 = model%dev_ptr(d)
      rel = 0.0_dp
      if (model%dev_ptr(d + 1) == k0) return
      rel = model%dev_coef(k0)*y(model%dev_dof(k0))
      do k = k0 + 1, model%dev_ptr(d + 1) - 1
         rel = rel + model%dev_coef(k)*y(model%dev_dof(k))
      end do
   end function device_relative

   !> |b_d|' |y| (coefficients and values by their magnitude): the scale of b_d' y, against
   !> which its rounding is judged.
   pure real(dp) function device_abs_relative(model, d, y) result(rel)
      type(model_type), intent(in) :: model   !! the model
      integer, intent(in) :: d                !! device
      real(dp), intent(in) :: y(:)            !! values over the DOFs
      integer :: k, k0

      k0 = model%dev_ptr(d)
      rel = 0.0_dp
      if (model%dev_ptr(d + 1) == k0) return
      rel = abs(model%dev_coef(k0))*abs(y(model%dev_dof(k0)))
      do k = k0 + 1, model%dev_ptr(d + 1) - 1
         rel = rel + abs(model%dev_coef(k))*abs(y(model%dev_dof(k)))
      end do
   end function device_abs_relative

   !> y = y + alpha b_d.
   pure subroutine add_device(model, d, alpha, y)
      type(model_type), intent(in) :: model   !! the model
      integer, intent(in) :: d                !! device
      real(dp), intent(in) :: alpha           !! factor of b_d
      real(dp), intent(inout) :: y(:)         !! vector over the DOFs
      integer :: k

      do k = model%dev_ptr(d), model%dev_ptr(d + 1) - 1
         y(model%dev_dof(k)) = y(model%dev_dof(k)) + alpha*model%dev_coef(k)
      end do
   end subroutine add_device

   !> b_d' M^-1 y for the lumped masses M: the relative acceleration across device d that
   !> forces y produce.
   pure real(dp) function device_inverse_mass_relative(model, d, y) result(rel)
      type(model_type), intent(in) :: model   !! the model
      integer, intent(in) :: d                !! device
      real(dp), intent(in) :: y(:)            !! forces on the DOFs [N]
      integer :: k, k0, i

      k0 = model%dev_ptr(d)
      rel = 0.0_dp
      if (model%dev_ptr(d + 1) == k0) return
      i = model%dev_dof(k0)
      rel = model%dev_coef(k0)*(y(i)/model%mass(i))
      do k = k0 + 1, model%dev_ptr(d + 1) - 1
         i = model%dev_dof(k)
         rel = rel + model%dev_coef(k)*(y(i)/model%mass(i))
      end do
   end function device_inverse_mass_relative

   !> |b_d|' M^-1 (scale y) (coefficients by their magnitude): a bound on b_d' M^-1 y's
   !> rounding when y holds magnitudes of forces, or the velocity change across the device
   !> that positive coefficients y make in a time scale.
   pure real(dp) function device_abs_inverse_mass_relative(model, d, y, scale) result(rel)
      type(model_type), intent(in) :: model   !! the model
      integer, intent(in) :: d                !! device
      real(dp), intent(in) :: y(:)            !! magnitudes on the DOFs [N, or N s/m]
      real(dp), intent(in), optional :: scale !! factor of y (default 1) [-, or s]
      real(dp) :: f
      integer :: k, k0, i

      k0 = model%dev_ptr(d)
      rel = 0.0_dp
      if (model%dev_ptr(d + 1) == k0) return
      f = 1.0_dp
      if (present(scale)) f = scale
      i = model%dev_dof(k0)
      rel = abs(model%dev_coef(k0))*(f*y(i)/model%mass(i))
      do k = k0 + 1, model%dev_ptr(d + 1) - 1
         i = model%dev_dof(k)
         rel = rel + abs(model%dev_coef(k))*(f*y(i)/model%mass(i))
      end do
   end function device_abs_inverse_mass_relative

   !> y = y + alpha |b_d| (coefficients by their magnitude).
   pure subroutine add_device_abs(model, d, alpha, y)
      type(model_type), intent(in) :: model   !! the model
      integer, intent(in) :: d                !! device
      real(dp), intent(in) :: alpha           !! factor of |b_d|
      real(dp), intent(inout) :: y(:)         !! vector over the DOFs
      integer :: k

      do k = model%dev_ptr(d), model%dev_ptr(d + 1) - 1
         y(model%dev_dof(k)) = y(model%dev_dof(k)) + alpha*abs(model%dev_coef(k))
      end do
   end subroutine add_device_abs

   !> b_a' M^-1 b_b: how a force across device b accelerates device a's relative motion.
   pure real(dp) function device_coupling(model, a, b) result(c)
      type(model_type), intent(in) :: model   !! the model
      integer, intent(in) :: a, b             !! devices
      integer :: k, l

      c = 0.0_dp
      do k = model%dev_ptr(a), model%dev_ptr(a + 1) - 1
         do l = model%dev_ptr(b), model%dev_ptr(b + 1) - 1
            if (model%dev_dof(k) == model%dev_dof(l)) &
               c = c + model%dev_coef(k)*model%dev_coef(l)/model%mass(model%dev_dof(k))
         end do
      end do
   end function device_coupling

   !> a = a + alpha b_d b_d' (a dense matrix over the DOFs).
   pure subroutine add_device_outer(model, d, alpha, a)
      type(model_type), intent(in) :: model   !! the model
      integer, intent(in) :: d                !! device
      real(dp), intent(in) :: alpha           !! factor
      real(dp), intent(inout) :: a(:, :)      !! matrix over the DOFs
      integer :: k, l

      do k = model%dev_ptr(d), model%dev_ptr(d + 1) - 1
         do l = model%dev_ptr(d), model%dev_ptr(d + 1) - 1
            a(model%dev_dof(k), model%dev_dof(l)) = a(model%dev_dof(k), model%dev_dof(l)) + &
                                                    alpha*model%dev_coef(k)*model%dev_coef(l)
         end do
      end do
   end subroutine add_device_outer

   !> The mass device d moves against its other end, 1 / (b' M^-1 b): m_i to the table,
   !> m_i m_j / (m_i + m_j) between two DOFs (the step limits' band floor, the mode of its
   !> sticking spring).
   pure real(dp) function moved_mass(model, d) result(m)
      type(model_type), intent(in) :: model  !! the model
      integer, intent(in) :: d               !! the device
      integer :: i, j

      call pair_nodes(model, d, i, j)
      if (i > 0) then
         m = model%mass(i)
         if (j > 0) m = model%mass(i)*model%mass(j)/(model%mass(i) + model%mass(j))
      else
         m = 1.0_dp/device_coupling(model, d, d)
      end if
   end function moved_mass

   !> The nodes of device d if it joins two (b_d = e_i - e_j, or e_i to the table): i
   !> (1..n_dof) and j (0..n_dof, 0 = the table); i = j = 0 if it does not.
   pure subroutine pair_nodes(model, d, i, j)
      type(model_type), intent(in) :: model  !! the model
      integer, intent(in) :: d               !! the device
      integer, intent(out) :: i, j           !! its nodes
      integer :: k0, nt

      i = 0; j = 0
      k0 = model%dev_ptr(d)
      nt = model%dev_ptr(d + 1) - k0
      if (nt == 1) then
         if (model%dev_coef(k0) == 1.0_dp) i = model%dev_dof(k0)
      else if (nt == 2) then
         if (model%dev_coef(k0) == 1.0_dp .and. model%dev_coef(k0 + 1) == -1.0_dp) then
            i = model%dev_dof(k0); j = model%dev_dof(k0 + 1)
         end if
      end if
   end subroutine pair_nodes

   !> The two nodes of every device (node_j = 0: the table), for the techniques and checks
   !> that treat devices as links between nodes; first = 0 when all devices join two nodes,
   !> else the first that does not (its nodes and those after it are 0).
   pure subroutine device_nodes(model, ni, nj, first)
      type(model_type), intent(in) :: model  !! the model
      integer, intent(out) :: ni(:)          !! first node of each device (1..n_dof)
      integer, intent(out) :: nj(:)          !! second node (0..n_dof)
      integer, intent(out) :: first          !! 0, or the first device not between two nodes
      integer :: d

      ni = 0
      nj = 0
      first = 0
      do d = 1, model%n_devices
         call pair_nodes(model, d, ni(d), nj(d))
         if (ni(d) == 0) then
            first = d
            return
         end if
      end do
   end subroutine device_nodes

   !> Whether every device of the model joins two nodes.
   pure logical function devices_are_pairs(model) result(pairs)
      type(model_type), intent(in) :: model  !! the model
      integer :: d, i, j

      pairs = .true.
      do d = 1, model%n_devices
         call pair_nodes(model, d, i, j)
         if (i == 0) then
            pairs = .false.
            return
         end if
      end do
   end function devices_are_pairs

end module fd_kinematics
