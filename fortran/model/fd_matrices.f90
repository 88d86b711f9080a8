!> System matrices: the springs' stiffness K, the viscous damping C (the paper's C = psi K
!> with psi = T xi / pi, or Rayleigh C = a0 M + a1 K), and the first mode of the stuck
!> system, in which every friction device is a rigid link.
module fd_matrices
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_real, fmt_int, stat_no_memory
   use fd_model, only: model_type, damping_none, damping_stiffness, damping_rayleigh
   use fd_modes, only: lowest_modes
   implicit none
   private

   public :: stiffness_matrix, damping_matrix, stuck_first_mode, structure_matrices, link_groups
   public :: system_modes, structure_damping

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   !> Stiffness matrix of the springs (relative coordinates; node 0 is the table).
   pure subroutine stiffness_matrix(model, k)
      type(model_type), intent(in) :: model !! the model
      real(dp), intent(out) :: k(:, :)      !! K [N/m], n_dof x n_dof
      integer :: s, i, j
      real(dp) :: ks

      k = 0.0_dp
      do s = 1, model%n_springs
         i = model%spring_i(s); j = model%spring_j(s); ks = model%spring_k(s)
         if (i > 0) k(i, i) = k(i, i) + ks
         if (j > 0) k(j, j) = k(j, j) + ks
         if (i > 0 .and. j > 0) then
            k(i, j) = k(i, j) - ks
            k(j, i) = k(j, i) - ks
         end if
      end do
   end subroutine stiffness_matrix

   !> The nev lowest natural modes of the structure with the devices flagged in `linked` made
   !> rigid links between their nodes (none: the free structure of springs alone; every device
   !> with P mu > 0: the stuck system). Linked nodes form one generalized DOF of their summed
   !> mass; a group joined to the table does not move. The reduced system is solved by
   !> fd_modes (dense for a few DOFs, else subspace iteration with a banded factor: memory
   !> linear in n_dof). Returns the eigenvalues w^2 (ascending), the M-normalized mode shapes
   !> over all DOFs (zero where locked to the table) and the number of moving groups nq.
   subroutine system_modes(model, linked, nev, omega2, phi, nq, error, path)
      type(model_type), intent(in) :: model          !! the model
      logical, intent(in) :: linked(:)               !! devices acting as rigid links
      integer, intent(in) :: nev                     !! modes wanted (at most nq are given)
      real(dp), intent(out) :: omega2(:)             !! w^2 [1/s^2], size nev (0 beyond nq)
      real(dp), intent(out) :: phi(:, :)             !! mode shapes, n_dof x nev
      integer, intent(out) :: nq                     !! moving groups (DOFs of the reduced system)
      type(error_type), allocatable, intent(out) :: error !! no free DOF, rigid-body mode, failure
      integer, intent(in), optional :: path          !! fd_modes' modes_auto (default), modes_dense, ...
      integer, allocatable :: grp(:), ea(:), eb(:)
      real(dp), allocatable :: mq(:), ek(:), lam(:), z(:, :)
      real(dp) :: scale
      integer :: n, i, s, a, b, ne, m, stat

      omega2 = 0.0_dp
      phi = 0.0_dp
      n = model%n_dof
      allocate (grp(n), stat=stat)
      if (stat /= 0) then
         nq = -1
         call no_memory(n); return
      end if
      call link_groups(model, linked, grp, nq)
      if (nq == 0) then
         call fatal_error(error, "the system has no free DOF: every mass is locked to the table by rigid links")
         return
      end if
      allocate (mq(nq), ea(model%n_springs), eb(model%n_springs), ek(model%n_springs), stat=stat)
      if (stat /= 0) then
         call no_memory(nq); return
      end if
      mq = 0.0_dp
      do i = 1, n
         if (grp(i) /= 0) mq(grp(i)) = mq(grp(i)) + model%mass(i)
      end do
      ne = 0
      do s = 1, model%n_springs
         a = group_of(model%spring_i(s)); b = group_of(model%spring_j(s))
         if (a == b) cycle                     ! inside one rigid group (or both on the table)
         ne = ne + 1
         ea(ne) = max(a, b); eb(ne) = min(a, b)
         ek(ne) = model%spring_k(s)
      end do
      m = min(nev, nq)
      allocate (lam(m), z(nq, m), stat=stat)
      if (stat /= 0) then
         call no_memory(nq); return
      end if
      call lowest_modes(mq, ea(1:ne), eb(1:ne), ek(1:ne), m, lam, z, scale, error, path)
      if (allocated(error)) return
      if (lam(1) <= 1.0e-12_dp*scale) then
         call fatal_error(error, "the system has a rigid-body mode (first eigenvalue "// &
                          trim(fmt_real(lam(1)))//"): a mass or group of masses has no spring to the table")
         return
      end if
      omega2(1:m) = lam
      do i = 1, n
         if (grp(i) /= 0) phi(i, 1:m) = z(grp(i), :)
      end do
   contains
      subroutine no_memory(size)
         integer, intent(in) :: size
         call fatal_error(error, "not enough memory for the eigenproblem of "//trim(fmt_int(size))// &
                          " DOFs", stat_no_memory)
      end subroutine no_memory
      pure integer function group_of(node)
         integer, intent(in) :: node
         group_of = 0
         if (node > 0) group_of = grp(node)
      end function group_of
   end subroutine system_modes

   !> First natural period of the stuck system (every device with P mu > 0 a rigid link
   !> between its nodes) and its mode shape.
   subroutine stuck_first_mode(model, period, phi, error)
      type(model_type), intent(in) :: model          !! the model
      real(dp), intent(out) :: period                !! first period T [s]
      real(dp), intent(out) :: phi(:)                !! first mode, all DOFs
      type(error_type), allocatable, intent(out) :: error !! no free DOF, or no stiffness
      real(dp) :: w2(1), z(model%n_dof, 1)
      integer :: nq

      period = 0.0_dp
      phi = 0.0_dp
      call system_modes(model, model%dev%p*model%dev%mu > 0.0_dp, 1, w2, z, nq, error)
      if (allocated(error)) then
         if (nq == 0) then
            error%message = "the stuck system has no free DOF: every mass is locked to the table &
                            &by friction devices, so its first period is undefined (give period in &damping)"
         else if (index(error%message, 'rigid-body mode') > 0) then
            error%message = "the stuck system has a rigid-body mode ("// &
                            error%message(index(error%message, 'first eigenvalue'):index(error%message, ')'))// &
                            ": add springs to the table or give period in &damping"
         end if
         return
      end if
      period = 2.0_dp*pi/sqrt(w2(1))
      phi = z(:, 1)
   end subroutine stuck_first_mode

   !> The damping of the model as C = a0 M + a1 K (K the springs), without forming a matrix:
   !> 'stiffness' a0 = 0, a1 = psi = T xi / pi; 'rayleigh' its a0, a1; 'none' 0, 0. Also the
   !> stuck system's first period and that mode's damping ratio phi' C phi / (2 w phi' M phi)
   !> (both 0 when the period is undefined and not needed). Memory linear in n_dof.
   subroutine structure_damping(model, a0, a1, period, xi, error)
      type(model_type), intent(in) :: model               !! the model
      real(dp), intent(out) :: a0                         !! mass factor of C [1/s]
      real(dp), intent(out) :: a1                         !! stiffness factor of C [s]
      real(dp), intent(out) :: period                     !! stuck first period [s], 0 if none
      real(dp), intent(out) :: xi                         !! its damping ratio
      type(error_type), allocatable, intent(out) :: error !! 'stiffness' damping without a period
      type(error_type), allocatable :: eig_error
      real(dp), allocatable :: phi(:)
      real(dp) :: t_damp, pkp, pmp
      integer :: s, i, j

      allocate (phi(model%n_dof))
      call stuck_first_mode(model, period, phi, eig_error)
      t_damp = period
      if (model%damping == damping_stiffness .and. model%period > 0.0_dp) then
         t_damp = model%period
      else if (model%damping == damping_stiffness .and. allocated(eig_error)) then
         call move_alloc(eig_error, error)
         error%message = "&damping: damping_type = 'stiffness' needs the stuck first period, but "// &
                         error%message
         return
      end if
      select case (model%damping)
      case (damping_stiffness)
         a0 = 0.0_dp
         a1 = t_damp*model%xi/pi
      case (damping_rayleigh)
         a0 = model%rayleigh_a0
         a1 = model%rayleigh_a1
      case default
         a0 = 0.0_dp
         a1 = 0.0_dp
      end select
      xi = 0.0_dp
      if (allocated(eig_error)) then
         period = 0.0_dp
         return
      end if
      pkp = 0.0_dp
      do s = 1, model%n_springs
         i = model%spring_i(s); j = model%spring_j(s)
         pkp = pkp + model%spring_k(s)*(node_value(i) - node_value(j))**2
      end do
      pmp = sum(model%mass*phi**2)
      xi = (a0*pmp + a1*pkp)/(2.0_dp*(2.0_dp*pi/period)*pmp)
   contains
      pure real(dp) function node_value(node)
         integer, intent(in) :: node
         node_value = 0.0_dp
         if (node > 0) node_value = phi(node)
      end function node_value
   end subroutine structure_damping

   !> Springs' stiffness K and damping C of the model as dense matrices (for the exact
   !> technique, whose models are small), with the stuck system's first period and that
   !> mode's damping ratio phi' C phi / (2 w phi' M phi) (0 when undefined).
   subroutine structure_matrices(model, k, c, period, xi, error)
      type(model_type), intent(in) :: model               !! the model
      real(dp), intent(out) :: k(:, :)                    !! K [N/m]
      real(dp), intent(out) :: c(:, :)                    !! C [N s/m]
      real(dp), intent(out) :: period                     !! stuck first period [s], 0 if none
      real(dp), intent(out) :: xi                         !! its damping ratio
      type(error_type), allocatable, intent(out) :: error !! 'stiffness' damping without a period
      type(error_type), allocatable :: eig_error
      real(dp), allocatable :: phi(:), cphi(:)
      real(dp) :: t_damp
      integer :: stat

      allocate (phi(model%n_dof), cphi(model%n_dof), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the matrices of "//trim(fmt_int(model%n_dof))//" DOFs", &
                          stat_no_memory)
         return
      end if
      call stiffness_matrix(model, k)
      call stuck_first_mode(model, period, phi, eig_error)
      ! the paper's psi = T xi / pi uses the given T, else the computed one
      t_damp = period
      if (model%damping == damping_stiffness .and. model%period > 0.0_dp) then
         t_damp = model%period
      else if (model%damping == damping_stiffness .and. allocated(eig_error)) then
         call move_alloc(eig_error, error)
         error%message = "&damping: damping_type = 'stiffness' needs the stuck first period, but "// &
                         error%message
         return
      end if
      call damping_matrix(model, k, t_damp, c)
      xi = 0.0_dp
      if (allocated(eig_error)) then
         period = 0.0_dp
      else
         cphi = matmul(c, phi)
         xi = dot_product(phi, cphi)/(2.0_dp*(2.0_dp*pi/period)*sum(model%mass*phi**2))
      end if
   end subroutine structure_matrices

   !> Groups of DOFs joined by rigid links (the devices flagged in `linked`), by union-find
   !> over the nodes 0..n_dof: grp(i) = 1..nq for a group that moves, 0 for a DOF linked
   !> (directly or through others) to the table.
   pure subroutine link_groups(model, linked, grp, nq)
      type(model_type), intent(in) :: model   !! the model
      logical, intent(in) :: linked(:)        !! devices acting as rigid links
      integer, intent(out) :: grp(:)          !! group of each DOF, 0 = with the table
      integer, intent(out) :: nq              !! number of moving groups
      integer :: root(0:model%n_dof), col(0:model%n_dof)
      integer :: d, i, a, b

      root = [(i, i=0, model%n_dof)]
      do d = 1, model%n_devices
         if (.not. linked(d)) cycle
         a = find(model%dev(d)%node_i); b = find(model%dev(d)%node_j)
         if (a /= b) root(max(a, b)) = min(a, b)
      end do
      col = 0
      nq = 0
      do i = 1, model%n_dof
         a = find(i)
         if (a /= 0 .and. col(a) == 0) then
            nq = nq + 1
            col(a) = nq
         end if
         grp(i) = col(a)
      end do
   contains
      pure integer function find(x)
         integer, intent(in) :: x
         find = x
         do while (root(find) /= find)
            find = root(find)
         end do
      end function find
   end subroutine link_groups

   !> Viscous damping matrix of the model.
   pure subroutine damping_matrix(model, k, period, c)
      type(model_type), intent(in) :: model !! the model
      real(dp), intent(in) :: k(:, :)       !! springs' stiffness
      real(dp), intent(in) :: period        !! stuck first period T [s] (for damping_stiffness)
      real(dp), intent(out) :: c(:, :)      !! C [N s/m]
      integer :: i

      select case (model%damping)
      case (damping_stiffness)
         c = (period*model%xi/pi)*k
      case (damping_rayleigh)
         c = model%rayleigh_a1*k
         do i = 1, model%n_dof
            c(i, i) = c(i, i) + model%rayleigh_a0*model%mass(i)
         end do
      case default
         c = 0.0_dp
      end select
   end subroutine damping_matrix

end module fd_matrices
