!> System matrices: the springs' stiffness K, the viscous damping C (the paper's C = psi K
!> with psi = T xi / pi, or Rayleigh C = a0 M + a1 K), and the first mode of the stuck
!> system, in which every friction device is a rigid link.
module fd_matrices
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_real, fmt_int, stat_no_memory
   use fd_model, only: model_type, damping_none, damping_stiffness, damping_rayleigh
   use fd_linalg, only: generalized_eigen
   implicit none
   private

   public :: stiffness_matrix, damping_matrix, stuck_first_mode, structure_matrices, link_groups

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

   !> First natural period of the stuck system (every device with P mu > 0 a rigid link
   !> between its nodes) and its mode shape, from the generalized symmetric eigenproblem.
   subroutine stuck_first_mode(model, k, period, phi, error)
      type(model_type), intent(in) :: model          !! the model
      real(dp), intent(in) :: k(:, :)                !! springs' stiffness
      real(dp), intent(out) :: period                !! first period T [s]
      real(dp), intent(out) :: phi(:)                !! first mode, all DOFs
      type(error_type), allocatable, intent(out) :: error !! no free DOF, or no stiffness
      integer, allocatable :: grp(:)
      real(dp), allocatable :: kq(:, :), mq(:, :), lam(:), z(:, :)
      integer :: n, nq, i, j, stat

      period = 0.0_dp
      phi = 0.0_dp
      n = model%n_dof
      allocate (grp(n), stat=stat)
      if (stat /= 0) then
         call no_memory(n); return
      end if
      call link_groups(model, model%dev%p*model%dev%mu > 0.0_dp, grp, nq)
      if (nq == 0) then
         call fatal_error(error, "the stuck system has no free DOF: every mass is locked to the table &
                          &by friction devices, so its first period is undefined (give period in &damping)")
         return
      end if
      allocate (kq(nq, nq), mq(nq, nq), lam(nq), z(nq, nq), stat=stat)
      if (stat /= 0) then
         call no_memory(nq); return
      end if
      ! K and M of the groups, T' K T and T' M T with T(i, grp(i)) = 1, summed entry by entry
      ! (no n x nq matrix T)
      kq = 0.0_dp
      mq = 0.0_dp
      do j = 1, n
         if (grp(j) == 0) cycle
         mq(grp(j), grp(j)) = mq(grp(j), grp(j)) + model%mass(j)
         do i = 1, n
            if (grp(i) /= 0) kq(grp(i), grp(j)) = kq(grp(i), grp(j)) + k(i, j)
         end do
      end do
      call generalized_eigen(kq, mq, lam, z, error)
      if (allocated(error)) return
      if (lam(1) <= 1.0e-12_dp*maxval(abs(lam))) then
         call fatal_error(error, "the stuck system has a rigid-body mode (first eigenvalue "// &
                          trim(fmt_real(lam(1)))//"): add springs to the table or give period in &damping")
         return
      end if
      period = 2.0_dp*pi/sqrt(lam(1))
      do i = 1, n
         if (grp(i) /= 0) phi(i) = z(grp(i), 1)
      end do
   contains
      subroutine no_memory(size)
         integer, intent(in) :: size
         call fatal_error(error, "not enough memory for the stuck system's eigenproblem of "// &
                          trim(fmt_int(size))//" DOFs", stat_no_memory)
      end subroutine no_memory
   end subroutine stuck_first_mode

   !> Springs' stiffness K and damping C of the model, with the stuck system's first period
   !> and that mode's damping ratio phi' C phi / (2 w phi' M phi) (0 when undefined).
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
      call stuck_first_mode(model, k, period, phi, eig_error)
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
