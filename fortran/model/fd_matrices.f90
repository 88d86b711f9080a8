!> System matrices: the springs' stiffness K, the viscous damping C (the paper's C = psi K
!> with psi = T xi / pi, or Rayleigh C = a0 M + a1 K), the first mode of the stuck
!> system, in which every friction device is a rigid link, and the natural modes of the
!> structure with every device stuck or free (natural_modes).
module fd_matrices
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_positive_inf, ieee_quiet_nan
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_real, fmt_int, stat_no_memory
   use fd_model, only: model_type, damping_none, damping_stiffness, damping_rayleigh, law_hysteretic, &
                       system_stuck, system_free
   use fd_linalg, only: generalized_eigen, lowest_eigen, lowest_eigen_band
   use fd_rcm, only: rcm_order
   implicit none
   private

   public :: stiffness_matrix, damping_matrix, stuck_first_mode, structure_matrices, link_groups
   public :: modes_type, natural_modes, stiffness_damping_factor
   public :: modes_none, modes_flexible, modes_rigid, modes_unrestrained

   ! what the eigenproblem of a system found
   integer, parameter :: modes_none = 0          !! not computed
   integer, parameter :: modes_flexible = 1      !! every mode has a finite period
   integer, parameter :: modes_rigid = 2         !! no free DOF: every mass held to the table
   integer, parameter :: modes_unrestrained = 3  !! a rigid-body mode (infinite period)

   !> Natural modes of the structure with every device stuck or free.
   type :: modes_type
      integer :: system = system_stuck          !! system_stuck or system_free
      integer :: status = modes_none            !! modes_flexible, modes_rigid, modes_unrestrained
      integer :: nq = 0                         !! modes of the system (its free DOFs)
      integer :: n = 0                          !! modes kept (the lowest n)
      real(dp), allocatable :: omega2(:)        !! w^2 [1/s2] (0 for a rigid-body mode)
      real(dp), allocatable :: period(:)        !! 2 pi / w [s] (+inf for a rigid-body mode)
      real(dp), allocatable :: shape(:, :)      !! (n_dof, n): largest component +1
      real(dp), allocatable :: mass_ratio(:)    !! effective modal mass / total mass [-]
      real(dp), allocatable :: xi(:)            !! damping ratio phi' C phi / (2 w phi' M phi) [-]
   end type modes_type

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

   !> Natural modes of the structure, K phi = w^2 M phi, the lowest nmax of them.
   !> system_stuck: every device with P mu > 0 in its sticking phase: a velocity-law or
   !> Coulomb device a rigid link between its nodes (as for the stuck first period), a
   !> hysteretic device its sticking spring P mu / f (the brace of a friction brace);
   !> system_free: every device removed. A system with no free DOF is rigid (no mode); an
   !> eigenvalue below 1e-12 of the largest is a rigid-body mode (w = 0, infinite period).
   !> Shapes are expanded to every DOF and scaled so that the component of largest
   !> magnitude is +1; the damping ratio of each mode is taken with the given C. Only the
   !> lowest nmax pairs are computed (LAPACK dsyevr on Mq^-1/2 Kq Mq^-1/2, Mq diagonal).
   subroutine natural_modes(model, k, c, system, nmax, modes, error)
      type(model_type), intent(in) :: model          !! the model
      real(dp), intent(in) :: k(:, :)                !! springs' stiffness
      real(dp), intent(in) :: c(:, :)                !! viscous damping
      integer, intent(in) :: system                  !! system_stuck or system_free
      integer, intent(in) :: nmax                    !! modes to keep at most
      type(modes_type), intent(out) :: modes         !! the modes
      type(error_type), allocatable, intent(out) :: error !! LAPACK failure
      integer, allocatable :: grp(:)
      logical, allocatable :: linked(:)
      real(dp), allocatable :: ks(:, :), kq(:, :), mq(:, :), cq(:, :), lam(:), z(:, :), phi(:), sq(:)
      real(dp) :: kd, big, w, pm, l, mtot
      integer :: n, nq, i, j, d, ni, nj, imax, kfirst, stat

      n = model%n_dof
      modes%system = system
      allocate (grp(n), linked(model%n_devices), ks(n, n), stat=stat)
      if (stat /= 0) then
         call no_memory(n); return
      end if
      ks = k
      do d = 1, model%n_devices
         pm = model%dev(d)%p*model%dev(d)%mu
         linked(d) = system == system_stuck .and. pm > 0.0_dp .and. model%dev(d)%law /= law_hysteretic
         if (system == system_stuck .and. pm > 0.0_dp .and. model%dev(d)%law == law_hysteretic) then
            kd = pm/model%dev(d)%f
            ni = model%dev(d)%node_i; nj = model%dev(d)%node_j
            ks(ni, ni) = ks(ni, ni) + kd
            if (nj > 0) then
               ks(nj, nj) = ks(nj, nj) + kd
               ks(ni, nj) = ks(ni, nj) - kd
               ks(nj, ni) = ks(nj, ni) - kd
            end if
         end if
      end do
      call link_groups(model, linked, grp, nq)
      modes%nq = nq
      if (nq == 0) then
         modes%status = modes_rigid
         allocate (modes%omega2(0), modes%period(0), modes%shape(n, 0), modes%mass_ratio(0), modes%xi(0))
         return
      end if
      ! Kq = T' K T, Cq = T' C T, Mq = T' M T by summing over the groups (T is 0/1: O(n^2))
      allocate (kq(nq, nq), cq(nq, nq), mq(nq, nq), sq(nq), stat=stat)
      if (stat /= 0) then
         call no_memory(nq); return
      end if
      kq = 0.0_dp; cq = 0.0_dp; mq = 0.0_dp
      do j = 1, n
         if (grp(j) == 0) cycle
         do i = 1, n
            if (grp(i) == 0) cycle
            kq(grp(i), grp(j)) = kq(grp(i), grp(j)) + ks(i, j)
            cq(grp(i), grp(j)) = cq(grp(i), grp(j)) + c(i, j)
         end do
         mq(grp(j), grp(j)) = mq(grp(j), grp(j)) + model%mass(j)
      end do
      ! M is diagonal in the reduced coordinates: the standard problem of Mq^-1/2 Kq Mq^-1/2,
      ! whose lowest pairs alone are computed; z = Mq^-1/2 y is M-normalized
      modes%n = min(max(nmax, 0), nq)
      do i = 1, nq
         sq(i) = 1.0_dp/sqrt(mq(i, i))
      end do
      do j = 1, nq
         kq(:, j) = sq*kq(:, j)*sq(j)
      end do
      ! a rigid-body mode: an eigenvalue below 1e-12 of the largest (bounded by the norm)
      big = 0.0_dp
      do j = 1, nq
         big = max(big, sum(abs(kq(:, j))))
      end do
      kfirst = max(modes%n, 1)
      allocate (lam(kfirst), z(nq, kfirst), stat=stat)
      if (stat /= 0) then
         call no_memory(nq); return
      end if
      call lowest_pairs(kq, kfirst, lam, z, error)
      if (allocated(error)) return
      do j = 1, kfirst
         z(:, j) = sq*z(:, j)
      end do
      modes%status = modes_flexible
      if (lam(1) <= 1.0e-12_dp*big) modes%status = modes_unrestrained
      allocate (modes%omega2(modes%n), modes%period(modes%n), modes%shape(n, modes%n), &
                modes%mass_ratio(modes%n), modes%xi(modes%n), phi(n), stat=stat)
      if (stat /= 0) then
         call no_memory(n); return
      end if
      mtot = sum(model%mass)
      do j = 1, modes%n
         do i = 1, n
            phi(i) = 0.0_dp
            if (grp(i) /= 0) phi(i) = z(grp(i), j)
         end do
         imax = maxloc(abs(phi), 1)
         phi = phi/phi(imax)
         modes%shape(:, j) = phi
         l = sum(model%mass*phi)
         modes%mass_ratio(j) = l*l/sum(model%mass*phi**2)/mtot
         if (lam(j) <= 1.0e-12_dp*big) then
            modes%omega2(j) = 0.0_dp
            modes%period(j) = ieee_value(1.0_dp, ieee_positive_inf)
            modes%xi(j) = ieee_value(1.0_dp, ieee_quiet_nan)
         else
            modes%omega2(j) = lam(j)
            w = sqrt(lam(j))
            modes%period(j) = 2.0_dp*pi/w
            ! z is M-normalized in the reduced coordinates: z' Mq z = 1
            modes%xi(j) = dot_product(z(:, j), matmul(cq, z(:, j)))/(2.0_dp*w)
         end if
      end do
   contains
      subroutine no_memory(size)
         integer, intent(in) :: size
         call fatal_error(error, "not enough memory for the natural modes of "//trim(fmt_int(size))// &
                          " DOFs (an eigenproblem of that size)", stat_no_memory)
      end subroutine no_memory
   end subroutine natural_modes

   !> The k lowest eigenpairs of a symmetric matrix: in band storage after a reverse
   !> Cuthill-McKee ordering when its bandwidth is small (a building: 1 to a few), O(n b^2);
   !> as a dense matrix otherwise.
   subroutine lowest_pairs(a, k, lambda, vec, error)
      real(dp), intent(in) :: a(:, :)
      integer, intent(in) :: k
      real(dp), intent(out) :: lambda(:), vec(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: ei(:), ej(:), perm(:), inv(:)
      real(dp), allocatable :: ab(:, :), vp(:, :)
      integer :: n, i, j, ne, bw, stat

      n = size(a, 1)
      ne = 0
      do j = 1, n
         do i = 1, j - 1
            if (a(i, j) /= 0.0_dp) ne = ne + 1
         end do
      end do
      allocate (ei(ne), ej(ne), perm(n), inv(n), stat=stat)
      if (stat /= 0) then
         call no_memory(); return
      end if
      ne = 0
      do j = 1, n
         do i = 1, j - 1
            if (a(i, j) == 0.0_dp) cycle
            ne = ne + 1
            ei(ne) = i; ej(ne) = j
         end do
      end do
      call rcm_order(n, ei, ej, perm)
      inv(perm) = [(i, i=1, n)]
      bw = 0
      do i = 1, ne
         bw = max(bw, abs(inv(ei(i)) - inv(ej(i))))
      end do
      if (n < 32 .or. 4*bw > n) then
         call lowest_eigen(a, k, lambda, vec, error)
         return
      end if
      allocate (ab(bw + 1, n), vp(n, k), stat=stat)
      if (stat /= 0) then
         call no_memory(); return
      end if
      ab = 0.0_dp
      do j = 1, n
         do i = max(1, j - bw), j
            ab(bw + 1 + i - j, j) = a(perm(i), perm(j))
         end do
      end do
      call lowest_eigen_band(ab, k, lambda, vp, error)
      if (allocated(error)) return
      vec(perm, :) = vp
   contains
      subroutine no_memory()
         call fatal_error(error, "not enough memory for the natural modes of "//trim(fmt_int(n))// &
                          " DOFs (an eigenproblem of that size)", stat_no_memory)
      end subroutine no_memory
   end subroutine lowest_pairs

   !> The factor b of the stiffness-proportional part of C = a0 M + b K: psi = T xi / pi
   !> ('stiffness': T the given period, else the stuck first period), a1 ('rayleigh'), 0
   !> ('none'). A spring k carries the viscous force b k times its rate of deformation.
   pure real(dp) function stiffness_damping_factor(model, period) result(b)
      type(model_type), intent(in) :: model  !! the model
      real(dp), intent(in) :: period         !! stuck first period [s] (for 'stiffness')

      select case (model%damping)
      case (damping_stiffness)
         if (model%period > 0.0_dp) then
            b = model%period*model%xi/pi
         else
            b = period*model%xi/pi
         end if
      case (damping_rayleigh)
         b = model%rayleigh_a1
      case default
         b = 0.0_dp
      end select
   end function stiffness_damping_factor

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
