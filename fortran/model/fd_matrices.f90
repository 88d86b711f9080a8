!> System matrices: the springs' stiffness K, the viscous damping C (the paper's C = psi K
!> with psi = T xi / pi, or Rayleigh C = a0 M + a1 K), the first mode of the stuck
!> system, in which every friction device is a rigid link, and the natural modes of the
!> structure with every device stuck or free (natural_modes).
module fd_matrices
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_positive_inf, ieee_quiet_nan
   use, intrinsic :: iso_fortran_env, only: int64
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_real, fmt_int, stat_no_memory
   use fd_model, only: model_type, damping_none, damping_stiffness, damping_rayleigh, damping_modal, &
                       system_stuck, system_free
   use fd_friction, only: sticking_stiffness, holds_when_stuck, links_when_stuck
   use fd_linalg, only: generalized_eigen, lowest_eigen, lowest_eigen_band
   use fd_rcm, only: rcm_order
   use fd_lapack, only: dpbtrf
   use fd_modes, only: lowest_modes, general_lowest_modes, modes_auto, modes_dense
   use fd_kinematics, only: add_device_outer, pair_nodes, devices_are_pairs
   use fd_stiffness, only: add_general_dense, general_form, influence_of
   implicit none
   private

   public :: stiffness_matrix, damping_matrix, stuck_first_mode, structure_matrices, link_groups
   public :: system_modes, structure_damping, stiffness_pivot
   public :: modes_type, natural_modes, natural_modes_sparse, stiffness_damping_factor
   public :: modes_none, modes_flexible, modes_rigid, modes_unrestrained
   public :: modes_dense_dofs, modes_kept, mode_damping, mode_participation, device_null_space

   !> Above this many DOFs the modes are found without an n x n matrix (natural_modes_sparse):
   !> the dense matrices would make peak memory grow as n**2
   integer, parameter :: modes_dense_dofs = 200

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

   !> The modes a system's summary holds that an estimate can use: its n kept modes when it
   !> has modes (flexible or unrestrained), else 0 (rigid, not computed).
   pure integer function modes_kept(modes) result(k)
      type(modes_type), intent(in) :: modes !! the system's modes

      k = 0
      if (modes%status == modes_flexible .or. modes%status == modes_unrestrained) k = max(modes%n, 0)
   end function modes_kept

   !> Damping per unit modal mass phi' C phi / phi' M phi of mode k: 2 xi wn; for a rigid-body
   !> mode (its damping ratio undefined: NaN) a0 of C = a0 M + a1 K, since K phi = 0 (not
   !> a0 + a1 wn^2 for every mode: the stuck system's K holds the sticking springs, which C's
   !> K does not).
   pure real(dp) function mode_damping(modes, k, a0) result(c)
      type(modes_type), intent(in) :: modes !! the system's modes
      integer, intent(in) :: k              !! the mode
      real(dp), intent(in) :: a0            !! C's mass factor [1/s]

      if (modes%omega2(k) > 0.0_dp) then
         c = 2.0_dp*modes%xi(k)*sqrt(modes%omega2(k))
      else
         c = a0
      end if
   end function mode_damping

   !> Participation of mode k in a motion of the table along r (default: every DOF along
   !> it, r = 1): phi' M r / phi' M phi.
   pure real(dp) function mode_participation(modes, k, mass, influence) result(g)
      type(modes_type), intent(in) :: modes !! the system's modes
      integer, intent(in) :: k              !! the mode
      real(dp), intent(in) :: mass(:)       !! the DOFs' masses [kg]
      real(dp), intent(in), optional :: influence(:) !! r [-]

      if (present(influence)) then
         g = sum(mass*influence*modes%shape(:, k))/sum(mass*modes%shape(:, k)**2)
      else
         g = sum(mass*modes%shape(:, k))/sum(mass*modes%shape(:, k)**2)
      end if
   end function mode_participation

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
      call add_general_dense(model, k)
   end subroutine stiffness_matrix

   !> Whether the structure's stiffness K (the springs and K_x, as stiffness_matrix) is
   !> positive definite, by its Cholesky factor in band storage (LAPACK dpbtrf) in the
   !> ordering of the smaller half-bandwidth kb, the DOFs' own (on a tie) or reverse
   !> Cuthill-McKee's: time O(n kb^2) and memory O(n kb), as the run's own factor, at every
   !> size. dof = 0 when it is; else the DOF (the model's numbering) of the first pivot that
   !> is not positive, or whose square is below 4 (kb + 1) eps of its diagonal (singular to
   !> working precision, as fd_banded judges K^): a DOF of a mechanism, or where an
   !> indefinite K fails.
   subroutine stiffness_pivot(model, dof, error)
      type(model_type), intent(in) :: model               !! the model
      integer, intent(out) :: dof                         !! 0, or the failing DOF
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      integer, allocatable :: ei(:), ej(:), perm(:), inv(:)
      real(dp), allocatable :: ab(:, :), diag(:)
      integer :: n, ne, e, i, j, kb, kb_rcm, info, stat

      dof = 0
      n = model%n_dof
      if (n < 1) return
      ne = 0
      allocate (ei(model%n_springs + model%n_kx), ej(model%n_springs + model%n_kx), perm(n), inv(n), stat=stat)
      if (stat /= 0) then
         call no_memory(); return
      end if
      do e = 1, model%n_springs
         ne = ne + 1
         ei(ne) = model%spring_i(e); ej(ne) = model%spring_j(e)
      end do
      do e = 1, model%n_kx
         ne = ne + 1
         ei(ne) = model%kx_i(e); ej(ne) = model%kx_j(e)
      end do
      inv = [(i, i=1, n)]
      kb = band_of(inv)
      call rcm_order(n, ei(1:ne), ej(1:ne), perm)
      inv(perm) = [(i, i=1, n)]
      kb_rcm = band_of(inv)
      if (kb_rcm >= kb) then
         perm = [(i, i=1, n)]
         inv = perm
      else
         kb = kb_rcm
      end if
      if (int(kb + 1, int64)*n > int(huge(n), int64)) then
         call no_memory(); return
      end if
      allocate (ab(kb + 1, n), diag(n), stat=stat)
      if (stat /= 0) then
         call no_memory(); return
      end if
      ab = 0.0_dp
      do e = 1, model%n_springs
         i = model%spring_i(e); j = model%spring_j(e)
         if (i > 0) call add_entry(inv(i), inv(i), model%spring_k(e))
         if (j > 0) call add_entry(inv(j), inv(j), model%spring_k(e))
         if (i > 0 .and. j > 0) call add_entry(inv(i), inv(j), -model%spring_k(e))
      end do
      do e = 1, model%n_kx
         call add_entry(inv(model%kx_i(e)), inv(model%kx_j(e)), model%kx_v(e))
      end do
      diag = ab(kb + 1, :)
      call dpbtrf('U', n, kb, ab, kb + 1, info)
      if (info > 0) then
         dof = perm(info)
         return
      end if
      do j = 1, n
         if (ab(kb + 1, j)**2 <= 4.0_dp*(kb + 1)*epsilon(1.0_dp)*diag(j)) then
            dof = perm(j)
            return
         end if
      end do
   contains
      !> The half-bandwidth of K's graph in the numbering new = num(old).
      pure integer function band_of(num) result(b)
         integer, intent(in) :: num(:)
         integer :: k
         b = 0
         do k = 1, ne
            if (ei(k) > 0 .and. ej(k) > 0) b = max(b, abs(num(ei(k)) - num(ej(k))))
         end do
      end function band_of
      !> K(p, q) = K(p, q) + v in the new numbering, by its entry on or above the diagonal.
      subroutine add_entry(p, q, v)
         integer, intent(in) :: p, q
         real(dp), intent(in) :: v
         ab(kb + 1 + min(p, q) - max(p, q), max(p, q)) = ab(kb + 1 + min(p, q) - max(p, q), max(p, q)) + v
      end subroutine add_entry
      subroutine no_memory()
         call fatal_error(error, "not enough memory for the banded factor of K, "//trim(fmt_int(n))//" DOFs", &
                          stat_no_memory)
      end subroutine no_memory
   end subroutine stiffness_pivot

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
      integer :: n, i, s, ne, m, stat, mode

      omega2 = 0.0_dp
      phi = 0.0_dp
      n = model%n_dof
      if (model%n_kx > 0 .or. .not. devices_are_pairs(model)) then
         ! stiffness beyond springs, or devices that are no links between two nodes: the
         ! dense (K, M) on the null space of the links up to modes_dense_dofs, else banded
         mode = modes_auto
         if (present(path)) mode = path
         call general_system_modes(model, linked, nev, mode == modes_dense .or. &
                                   (mode == modes_auto .and. n <= modes_dense_dofs), omega2, phi, nq, error)
         return
      end if
      allocate (grp(n), stat=stat)
      if (stat /= 0) then
         nq = -1
         call out_of_memory('eigenproblem', n, error); return
      end if
      call link_groups(model, linked, grp, nq)
      if (nq == 0) then
         call fatal_error(error, "the system has no free DOF: every mass is locked to the table by rigid links")
         return
      end if
      allocate (mq(nq), ea(model%n_springs), eb(model%n_springs), ek(model%n_springs), stat=stat)
      if (stat /= 0) then
         call out_of_memory('eigenproblem', nq, error); return
      end if
      call group_masses(grp, model%mass, mq)
      ne = 0
      do s = 1, model%n_springs
         call add_element(grp, model%spring_i(s), model%spring_j(s), model%spring_k(s), ea, eb, ek, ne)
      end do
      m = min(nev, nq)
      allocate (lam(m), z(nq, m), stat=stat)
      if (stat /= 0) then
         call out_of_memory('eigenproblem', nq, error); return
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
   end subroutine system_modes

   !> First natural period of the stuck system (every device that holds its nodes together
   !> while it sticks, holds_when_stuck, a rigid link between them) and its mode shape.
   subroutine stuck_first_mode(model, period, phi, error)
      type(model_type), intent(in) :: model          !! the model
      real(dp), intent(out) :: period                !! first period T [s]
      real(dp), intent(out) :: phi(:)                !! first mode, all DOFs
      type(error_type), allocatable, intent(out) :: error !! no free DOF, or no stiffness
      real(dp) :: w2(1), z(model%n_dof, 1)
      integer :: nq

      period = 0.0_dp
      phi = 0.0_dp
      call system_modes(model, holds_when_stuck(model%dev), 1, w2, z, nq, error)
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
      call damping_period(model, period, eig_error, t_damp, error)
      if (allocated(error)) return
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
      if (model%n_kx > 0) pkp = pkp + general_form(model, phi, phi)
      pmp = sum(model%mass*phi**2)
      xi = (a0*pmp + a1*pkp)/(2.0_dp*(2.0_dp*pi/period)*pmp)
      ! 'modal' damping's low-rank term: phi' U diag(d) U' phi
      if (allocated(model%modal_d)) xi = xi + sum(model%modal_d*matmul(phi, model%modal_u)**2)/ &
                                         (2.0_dp*(2.0_dp*pi/period)*pmp)
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
      call damping_period(model, period, eig_error, t_damp, error)
      if (allocated(error)) return
      call damping_matrix(model, k, t_damp, c)
      xi = 0.0_dp
      if (allocated(eig_error)) then
         period = 0.0_dp
      else
         cphi = matmul(c, phi)
         xi = dot_product(phi, cphi)/(2.0_dp*(2.0_dp*pi/period)*sum(model%mass*phi**2))
      end if
   end subroutine structure_matrices

   !> The period T of the paper's damping psi = T xi / pi: the deck's (model%period), else
   !> the stuck first period; for damping 'stiffness' without either, an error (the stuck
   !> first mode's, which eig_error holds, moved into it).
   subroutine damping_period(model, period, eig_error, t_damp, error)
      type(model_type), intent(in) :: model                    !! the model
      real(dp), intent(in) :: period                           !! stuck first period [s]
      type(error_type), allocatable, intent(inout) :: eig_error !! why it has none (stuck_first_mode)
      real(dp), intent(out) :: t_damp                          !! T [s]
      type(error_type), allocatable, intent(out) :: error      !! 'stiffness' damping without a period

      t_damp = period
      if (model%damping == damping_stiffness .and. model%period > 0.0_dp) then
         t_damp = model%period
      else if (model%damping == damping_stiffness .and. allocated(eig_error)) then
         call move_alloc(eig_error, error)
         error%message = "&damping: damping_type = 'stiffness' needs the stuck first period, but "// &
                         error%message
      end if
   end subroutine damping_period

   !> system_modes of a general model (stiffness K_x, or devices with any direction b_d): the
   !> devices in `linked` are the constraints b_d' u = 0, and the modes those of (K, M) on
   !> their null space. Dense: of the dense (K, M) (constrained_modes). Otherwise without an
   !> n x n matrix, by fd_modes' general_lowest_modes (subspace iteration with the banded
   !> factor of K, the constraints through their r x r Schur complement).
   subroutine general_system_modes(model, linked, nev, dense, omega2, phi, nq, error)
      type(model_type), intent(in) :: model          !! the model
      logical, intent(in) :: linked(:)               !! devices acting as rigid links
      integer, intent(in) :: nev                     !! modes wanted
      logical, intent(in) :: dense                   !! the dense eigenproblem, else the banded one
      real(dp), intent(out) :: omega2(:)             !! w^2 [1/s^2], size nev (0 beyond nq)
      real(dp), intent(out) :: phi(:, :)             !! M-normalized mode shapes, n_dof x nev
      integer, intent(out) :: nq                     !! free DOFs of the constrained system
      type(error_type), allocatable, intent(out) :: error !! no free DOF, rigid-body mode
      real(dp), allocatable :: k(:, :), lam(:), z(:, :), kd(:), kv(:)
      integer, allocatable :: ki(:), kj(:)
      real(dp) :: big, lowest
      integer :: n, m, j, stat

      n = model%n_dof
      if (dense) then
         allocate (k(n, n), lam(n), z(n, n), stat=stat)
         if (stat /= 0) then
            nq = -1
            call out_of_memory('eigenproblem', n, error)
            return
         end if
         call stiffness_matrix(model, k)
         big = 0.0_dp
         do j = 1, n
            big = max(big, sum(abs(k(:, j)))/model%mass(j))
         end do
         call constrained_modes(model, k, linked, lam, z, nq, error)
      else
         allocate (kd(model%n_devices))
         kd = 0.0_dp
         call kx_entries(model, ki, kj, kv)
         call general_lowest_modes(model%mass, model%spring_i(1:model%n_springs), model%spring_j(1:model%n_springs), &
                                   model%spring_k(1:model%n_springs), ki, kj, kv, model%dev_ptr, model%dev_dof, &
                                   model%dev_coef, kd, linked, nev, omega2, phi, nq, big, error)
      end if
      if (allocated(error)) return
      if (nq == 0) then
         call fatal_error(error, "the system has no free DOF: every mass is locked to the table by rigid links")
         return
      end if
      if (dense) then
         lowest = lam(1)
      else
         lowest = omega2(1)
      end if
      if (lowest <= 1.0e-12_dp*big) then
         call fatal_error(error, "the system has a rigid-body mode (first eigenvalue "// &
                          trim(fmt_real(lowest))//"): a mass or group of masses has no spring to the table")
         return
      end if
      if (.not. dense) return
      m = min(nev, nq)
      omega2(1:m) = lam(1:m)
      phi(:, 1:m) = z(:, 1:m)
   end subroutine general_system_modes

   !> K_x's entries (kx_i, kx_j, kx_v) as arrays of n_kx entries (none when it has none).
   pure subroutine kx_entries(model, ki, kj, kv)
      type(model_type), intent(in) :: model            !! the model
      integer, allocatable, intent(out) :: ki(:), kj(:) !! rows, columns (ki <= kj)
      real(dp), allocatable, intent(out) :: kv(:)       !! values

      if (model%n_kx > 0) then
         ki = model%kx_i(1:model%n_kx)
         kj = model%kx_j(1:model%n_kx)
         kv = model%kx_v(1:model%n_kx)
      else
         allocate (ki(0), kj(0), kv(0))
      end if
   end subroutine kx_entries

   !> Z, an orthonormal basis of the null space of the directions b_d of the devices in
   !> `linked` (b_d' Z = 0): the eigenvectors of B B' (B = [b_d]) whose eigenvalue is below
   !> 1e-12 of the largest; the identity when no linked device has a direction. nq its
   !> columns (-1 when the memory is refused).
   subroutine device_null_space(model, linked, z, nq, error)
      type(model_type), intent(in) :: model          !! the model (directions)
      logical, intent(in) :: linked(:)               !! the devices that constrain
      real(dp), allocatable, intent(out) :: z(:, :)  !! (n_dof, nq)
      integer, intent(out) :: nq                     !! dimension of the null space
      type(error_type), allocatable, intent(out) :: error !! LAPACK failure, no memory
      real(dp), allocatable :: bb(:, :), eye(:, :), ev(:), vec(:, :)
      integer :: n, d, i, stat

      n = model%n_dof
      allocate (bb(n, n), eye(n, n), ev(n), vec(n, n), stat=stat)
      if (stat /= 0) then
         nq = -1
         call out_of_memory('eigenproblem', n, error)
         return
      end if
      bb = 0.0_dp
      eye = 0.0_dp
      do i = 1, n
         eye(i, i) = 1.0_dp
      end do
      do d = 1, size(linked)
         if (linked(d)) call add_device_outer(model, d, 1.0_dp, bb)
      end do
      if (any(bb /= 0.0_dp)) then
         call generalized_eigen(bb, eye, ev, vec, error)
         if (allocated(error)) return
         nq = count(ev <= 1.0e-12_dp*maxval(abs(ev)))
         z = vec(:, 1:nq)
      else
         nq = n
         z = eye
      end if
   end subroutine device_null_space

   !> The modes of K u = w^2 M u under the constraints b_d' u = 0 of the devices in `linked`:
   !> Z an orthonormal basis of their null space (the eigenvectors of B B' whose eigenvalue
   !> is below 1e-12 of the largest, B = [b_d]), then (Z' K Z) y = w^2 (Z' M Z) y and
   !> phi = Z y, so that phi' M phi = 1. lam and the first nq columns of phi are set, nq the
   !> dimension of the null space (lam ascending).
   subroutine constrained_modes(model, k, linked, lam, phi, nq, error)
      type(model_type), intent(in) :: model          !! the model (masses, directions)
      real(dp), intent(in) :: k(:, :)                !! stiffness over the DOFs
      logical, intent(in) :: linked(:)               !! the devices that constrain
      real(dp), intent(out) :: lam(:)                !! w^2, ascending (n_dof)
      real(dp), intent(out) :: phi(:, :)             !! shapes (n_dof, n_dof), M-normalized
      integer, intent(out) :: nq                     !! free DOFs
      type(error_type), allocatable, intent(out) :: error !! LAPACK failure, no memory
      real(dp), allocatable :: z(:, :), kq(:, :), mq(:, :), y(:, :), col(:)
      integer :: n, i, j, stat

      n = model%n_dof
      lam = 0.0_dp
      phi = 0.0_dp
      call device_null_space(model, linked, z, nq, error)
      if (allocated(error) .or. nq == 0) return
      allocate (kq(nq, nq), mq(nq, nq), y(nq, nq), col(n), stat=stat)
      if (stat /= 0) then
         call out_of_memory('eigenproblem', nq, error)
         return
      end if
      kq = matmul(transpose(z), matmul(k, z))
      do j = 1, nq
         col = model%mass*z(:, j)
         do i = 1, nq
            mq(i, j) = dot_product(z(:, i), col)
         end do
      end do
      kq = 0.5_dp*(kq + transpose(kq))
      mq = 0.5_dp*(mq + transpose(mq))
      call generalized_eigen(kq, mq, lam(1:nq), y, error)
      if (allocated(error)) return
      phi(:, 1:nq) = matmul(z, y)
   end subroutine constrained_modes

   !> natural_modes of a model whose devices are not all links between two nodes: the stuck
   !> system's linking devices as constraints and its hysteretic devices' sticking springs
   !> in K (constrained_modes); the same outputs as natural_modes.
   subroutine constrained_natural_modes(model, k, c, system, nmax, modes, error)
      type(model_type), intent(in) :: model          !! the model
      real(dp), intent(in) :: k(:, :)                !! stiffness over the DOFs (springs, K_x)
      real(dp), intent(in) :: c(:, :)                !! viscous damping
      integer, intent(in) :: system                  !! system_stuck or system_free
      integer, intent(in) :: nmax                    !! modes to keep at most
      type(modes_type), intent(inout) :: modes       !! the modes
      type(error_type), allocatable, intent(out) :: error !! LAPACK failure
      real(dp), allocatable :: ks(:, :), lam(:), z(:, :), zcz(:)
      logical, allocatable :: linked(:)
      real(dp) :: kd, big
      integer :: n, d, j, stat

      n = model%n_dof
      allocate (ks(n, n), lam(n), z(n, n), linked(model%n_devices), stat=stat)
      if (stat /= 0) then
         call out_of_memory('natural modes', n, error)
         return
      end if
      ks = k
      do d = 1, model%n_devices
         linked(d) = system == system_stuck .and. links_when_stuck(model%dev(d))
         kd = sticking_stiffness(model%dev(d))
         if (system == system_stuck .and. kd > 0.0_dp) call add_device_outer(model, d, kd, ks)
      end do
      call constrained_modes(model, ks, linked, lam, z, modes%nq, error)
      if (allocated(error)) return
      if (modes%nq == 0) then
         call no_free_dof(n, modes); return
      end if
      big = 0.0_dp
      do j = 1, n
         big = max(big, sum(abs(ks(:, j)))/model%mass(j))
      end do
      modes%n = min(max(nmax, 0), modes%nq)
      allocate (zcz(modes%n))
      do j = 1, modes%n
         zcz(j) = dot_product(z(:, j), matmul(c, z(:, j)))
      end do
      call store_dof_modes(model, lam, z, big, zcz, modes, error)
   end subroutine constrained_natural_modes

   !> natural_modes_sparse of a general model (K_x, devices of any direction) without an
   !> n x n matrix: the stuck system's linking devices as constraints and its sticking springs
   !> in K, by fd_modes' general_lowest_modes (banded factor, the constraints through their
   !> Schur complement); C = a0 M + a1 K (K the springs and K_x) and 'modal' damping's
   !> low-rank term give each mode's damping ratio. The same outputs as natural_modes.
   subroutine banded_natural_modes(model, a0, a1, system, nmax, modes, error)
      type(model_type), intent(in) :: model          !! the model
      real(dp), intent(in) :: a0, a1                 !! C = a0 M + a1 K
      integer, intent(in) :: system                  !! system_stuck or system_free
      integer, intent(in) :: nmax                    !! modes to keep at most
      type(modes_type), intent(inout) :: modes       !! the modes
      type(error_type), allocatable, intent(out) :: error !! solver failure, no memory
      real(dp), allocatable :: kd(:), kv(:), lam(:), z(:, :), zcz(:)
      integer, allocatable :: ki(:), kj(:)
      logical, allocatable :: linked(:)
      real(dp) :: big, w
      integer :: n, nd, ns, d, j, s, m, stat

      n = model%n_dof
      nd = model%n_devices
      ns = model%n_springs
      allocate (kd(nd), linked(nd), stat=stat)
      if (stat /= 0) then
         call out_of_memory('natural modes', n, error); return
      end if
      do d = 1, nd
         linked(d) = system == system_stuck .and. links_when_stuck(model%dev(d))
         kd(d) = 0.0_dp
         if (system == system_stuck) kd(d) = max(sticking_stiffness(model%dev(d)), 0.0_dp)
      end do
      m = max(min(nmax, n), 1)
      allocate (lam(m), z(n, m), stat=stat)
      if (stat /= 0) then
         call out_of_memory('natural modes', n, error); return
      end if
      call kx_entries(model, ki, kj, kv)
      call general_lowest_modes(model%mass, model%spring_i(1:ns), model%spring_j(1:ns), model%spring_k(1:ns), &
                                ki, kj, kv, model%dev_ptr, model%dev_dof, model%dev_coef, kd, linked, m, lam, z, &
                                modes%nq, big, error)
      if (allocated(error)) then
         error%message = "the natural modes of the "//trim(merge('stuck', 'free ', system == system_stuck))// &
                         " system: "//error%message
         return
      end if
      if (modes%nq == 0) then
         call no_free_dof(n, modes); return
      end if
      modes%n = min(max(nmax, 0), modes%nq)
      allocate (zcz(modes%n), stat=stat)
      if (stat /= 0) then
         call out_of_memory('natural modes', n, error); return
      end if
      ! z' C z = a0 + a1 z' K z (z' M z = 1), K the springs and K_x; 'modal' damping's z' U diag(d) U' z
      do j = 1, modes%n
         w = 0.0_dp
         do s = 1, ns
            w = w + model%spring_k(s)*(node_z(model%spring_i(s), j) - node_z(model%spring_j(s), j))**2
         end do
         zcz(j) = a0 + a1*(w + general_form(model, z(:, j), z(:, j)))
         if (allocated(model%modal_d)) zcz(j) = zcz(j) + sum(model%modal_d*matmul(z(:, j), model%modal_u)**2)
      end do
      call store_dof_modes(model, lam, z, big, zcz, modes, error)
   contains
      pure real(dp) function node_z(node, j)
         integer, intent(in) :: node, j
         node_z = 0.0_dp
         if (node > 0) node_z = z(node, j)
      end function node_z
   end subroutine banded_natural_modes

   !> Groups of DOFs joined by rigid links (the devices flagged in `linked`), by union-find
   !> over the nodes 0..n_dof: grp(i) = 1..nq for a group that moves, 0 for a DOF linked
   !> (directly or through others) to the table.
   pure subroutine link_groups(model, linked, grp, nq)
      type(model_type), intent(in) :: model   !! the model
      logical, intent(in) :: linked(:)        !! devices acting as rigid links
      integer, intent(out) :: grp(:)          !! group of each DOF, 0 = with the table
      integer, intent(out) :: nq              !! number of moving groups
      integer :: root(0:model%n_dof), col(0:model%n_dof)
      integer :: d, i, a, b, ni, nj

      root = [(i, i=0, model%n_dof)]
      do d = 1, model%n_devices
         if (.not. linked(d)) cycle
         call pair_nodes(model, d, ni, nj)
         if (ni == 0) cycle
         a = find(root, ni); b = find(root, nj)
         if (a /= b) root(max(a, b)) = min(a, b)
      end do
      col = 0
      nq = 0
      do i = 1, model%n_dof
         a = find(root, i)
         if (a /= 0 .and. col(a) == 0) then
            nq = nq + 1
            col(a) = nq
         end if
         grp(i) = col(a)
      end do
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
      real(dp), allocatable :: ks(:, :), kq(:, :), mq(:, :), cq(:, :), lam(:), z(:, :), sq(:), zcz(:)
      real(dp) :: kd, big
      integer :: n, nq, i, j, d, kfirst, stat

      n = model%n_dof
      modes%system = system
      if (.not. devices_are_pairs(model)) then
         call constrained_natural_modes(model, k, c, system, nmax, modes, error)
         return
      end if
      call system_groups(model, system, grp, modes, stat)
      if (stat == 0) allocate (ks(n, n), stat=stat)
      if (stat /= 0) then
         call out_of_memory('natural modes', n, error, ' (an eigenproblem of that size)'); return
      end if
      nq = modes%nq
      if (nq == 0) return
      ks = k
      do d = 1, model%n_devices
         kd = sticking_stiffness(model%dev(d))
         if (system == system_stuck .and. kd > 0.0_dp) then
            call add_device_outer(model, d, kd, ks)
         end if
      end do
      ! Kq = T' K T, Cq = T' C T, Mq = T' M T by summing over the groups (T is 0/1: O(n^2))
      allocate (kq(nq, nq), cq(nq, nq), mq(nq, nq), sq(nq), stat=stat)
      if (stat /= 0) then
         call out_of_memory('natural modes', nq, error, ' (an eigenproblem of that size)'); return
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
      allocate (lam(kfirst), z(nq, kfirst), zcz(modes%n), stat=stat)
      if (stat /= 0) then
         call out_of_memory('natural modes', nq, error, ' (an eigenproblem of that size)'); return
      end if
      call lowest_pairs(kq, kfirst, lam, z, error)
      if (allocated(error)) return
      do j = 1, kfirst
         z(:, j) = sq*z(:, j)
      end do
      modes%status = modes_flexible
      if (lam(1) <= 1.0e-12_dp*big) modes%status = modes_unrestrained
      ! z is M-normalized in the reduced coordinates: z' Mq z = 1
      do j = 1, modes%n
         zcz(j) = dot_product(z(:, j), matmul(cq, z(:, j)))
      end do
      call store_modes(grp, model%mass, lam, z, lam(1:modes%n) <= 1.0e-12_dp*big, zcz, modes, stat, model%influence)
      if (stat /= 0) call out_of_memory('natural modes', n, error, ' (an eigenproblem of that size)')
   end subroutine natural_modes

   !> The natural modes of a large model without an n x n matrix: the springs (and, stuck,
   !> the hysteretic devices' sticking stiffness) as elements of the reduced system of the
   !> rigid groups, whose lowest pairs fd_modes finds by subspace iteration with the banded
   !> factor. The damping C = a0 M + a1 K (K of the springs) gives xi from phi' K phi. A
   !> system with a rigid-body mode is shifted by sigma M (grounded springs sigma m), and
   !> the eigenvalues shifted back. The same results as natural_modes (to the solver's
   !> tolerance): status, periods, shapes, mass ratios, damping ratios.
   subroutine natural_modes_sparse(model, a0, a1, system, nmax, modes, error)
      type(model_type), intent(in) :: model          !! the model
      real(dp), intent(in) :: a0, a1                 !! C = a0 M + a1 K
      integer, intent(in) :: system                  !! system_stuck or system_free
      integer, intent(in) :: nmax                    !! modes to keep at most
      type(modes_type), intent(out) :: modes         !! the modes
      type(error_type), allocatable, intent(out) :: error !! solver failure, no memory
      integer, allocatable :: grp(:), ea(:), eb(:), root(:)
      logical, allocatable :: grounded(:)
      real(dp), allocatable :: mq(:), ek(:), lam(:), z(:, :), ebig(:), zcz(:)
      real(dp) :: kd, big, sigma, scale, w, kz
      integer :: n, nq, ne, ns, nd, i, j, a, b, s, d, m, stat, ni, nj
      logical :: shifted

      n = model%n_dof
      ns = model%n_springs
      nd = model%n_devices
      modes%system = system
      if (model%n_kx > 0 .or. .not. devices_are_pairs(model)) then
         ! stiffness beyond springs, or devices that are no links between two nodes
         call banded_natural_modes(model, a0, a1, system, nmax, modes, error)
         return
      end if
      call system_groups(model, system, grp, modes, stat)
      if (stat == 0) allocate (ea(ns + nd + n), eb(ns + nd + n), ek(ns + nd + n), stat=stat)
      if (stat /= 0) then
         call out_of_memory('natural modes', n, error); return
      end if
      nq = modes%nq
      if (nq == 0) return
      allocate (mq(nq), root(0:nq), grounded(0:nq), ebig(nq), stat=stat)
      if (stat /= 0) then
         call out_of_memory('natural modes', nq, error); return
      end if
      call group_masses(grp, model%mass, mq)
      ne = 0
      do s = 1, ns
         call add_element(grp, model%spring_i(s), model%spring_j(s), model%spring_k(s), ea, eb, ek, ne)
      end do
      if (system == system_stuck) then
         do d = 1, nd
            kd = sticking_stiffness(model%dev(d))
            if (kd <= 0.0_dp) cycle
            call pair_nodes(model, d, ni, nj)
            if (ni == 0) then
               call fatal_error(error, "the sparse modes of the stuck system take devices between two nodes; "// &
                                "device "//trim(fmt_int(d))//" is not")
               return
            end if
            call add_element(grp, ni, nj, kd, ea, eb, ek, ne)
         end do
      end if
      ! a bound of the largest eigenvalue of Mq^-1 Kq (Gershgorin), and the groups held to
      ! the table through elements (the others move as a rigid body)
      ebig = 0.0_dp
      root = [(i, i=0, nq)]
      do i = 1, ne
         a = ea(i); b = eb(i)
         ebig(a) = ebig(a) + 2.0_dp*ek(i)/mq(a)
         if (b > 0) ebig(b) = ebig(b) + 2.0_dp*ek(i)/mq(b)
         if (ek(i) <= 0.0_dp) cycle
         a = find(root, a); b = find(root, b)
         if (a /= b) root(max(a, b)) = min(a, b)
      end do
      big = maxval(ebig)
      grounded = .false.
      do i = 1, nq
         grounded(i) = find(root, i) == 0
      end do
      shifted = .not. all(grounded(1:nq))
      sigma = 0.0_dp
      if (shifted) then
         sigma = 1.0e-6_dp*max(big, tiny(1.0_dp))
         do i = 1, nq
            ne = ne + 1
            ea(ne) = i; eb(ne) = 0; ek(ne) = sigma*mq(i)
         end do
      end if
      modes%n = min(max(nmax, 0), nq)
      m = max(modes%n, 1)
      allocate (lam(m), z(nq, m), zcz(modes%n), stat=stat)
      if (stat /= 0) then
         call out_of_memory('natural modes', nq, error); return
      end if
      call lowest_modes(mq, ea(1:ne), eb(1:ne), ek(1:ne), m, lam, z, scale, error)
      if (allocated(error)) then
         error%message = "the natural modes of the "//trim(merge('stuck', 'free ', system == system_stuck))// &
                         " system: "//error%message
         return
      end if
      lam = lam - sigma
      big = max(big, scale)
      modes%status = modes_flexible
      if (shifted) modes%status = modes_unrestrained
      ! z' Cq z = a0 + a1 z' Kq z, Kq of the springs (z' Mq z = 1)
      do j = 1, modes%n
         kz = 0.0_dp
         do s = 1, ns
            w = node_z(model%spring_i(s), j) - node_z(model%spring_j(s), j)
            kz = kz + model%spring_k(s)*w*w
         end do
         zcz(j) = a0 + a1*kz
         ! 'modal' damping's low-rank term: z' U diag(d) U' z
         if (allocated(model%modal_d)) then
            do d = 1, size(model%modal_d)
               kz = 0.0_dp
               do i = 1, n
                  kz = kz + model%modal_u(i, d)*node_z(i, j)
               end do
               zcz(j) = zcz(j) + model%modal_d(d)*kz*kz
            end do
         end if
      end do
      call store_modes(grp, model%mass, lam, z, lam(1:modes%n) <= 1.0e-9_dp*big .and. shifted, zcz, modes, stat, &
                       model%influence)
      if (stat /= 0) call out_of_memory('natural modes', n, error)
   contains
      !> Component j of z at a node (0 on the table and in its group).
      pure real(dp) function node_z(node, j)
         integer, intent(in) :: node, j
         node_z = 0.0_dp
         if (node == 0) return
         if (grp(node) /= 0) node_z = z(grp(node), j)
      end function node_z
   end subroutine natural_modes_sparse

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
         call out_of_memory('natural modes', n, error, ' (an eigenproblem of that size)'); return
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
         call out_of_memory('natural modes', n, error, ' (an eigenproblem of that size)'); return
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
      integer :: i, j

      select case (model%damping)
      case (damping_stiffness)
         c = (period*model%xi/pi)*k
      case (damping_rayleigh)
         c = model%rayleigh_a1*k
         do i = 1, model%n_dof
            c(i, i) = c(i, i) + model%rayleigh_a0*model%mass(i)
         end do
      case (damping_modal)
         ! U diag(d) U' (a dense C only for the small models that use one)
         c = 0.0_dp
         do i = 1, size(model%modal_d)
            do j = 1, model%n_dof
               c(:, j) = c(:, j) + (model%modal_d(i)*model%modal_u(j, i))*model%modal_u(:, i)
            end do
         end do
      case default
         c = 0.0_dp
      end select
   end subroutine damping_matrix

   !> The mass of each rigid group (link_groups): the sum of its DOFs' masses.
   pure subroutine group_masses(grp, mass, mq)
      integer, intent(in) :: grp(:)          !! group of each DOF, 0 = with the table
      real(dp), intent(in) :: mass(:)        !! masses of the DOFs
      real(dp), intent(out) :: mq(:)         !! mass of each group
      integer :: i

      mq = 0.0_dp
      do i = 1, size(grp)
         if (grp(i) /= 0) mq(grp(i)) = mq(grp(i)) + mass(i)
      end do
   end subroutine group_masses

   !> A spring k between nodes ni and nj (0 = the table) as an element of the reduced system
   !> of the rigid groups grp: (ea, eb, ek)(ne + 1) with ea > eb (eb = 0: the table); none
   !> when both nodes are in one group (or on the table).
   pure subroutine add_element(grp, ni, nj, k, ea, eb, ek, ne)
      integer, intent(in) :: grp(:)          !! group of each DOF, 0 = with the table
      integer, intent(in) :: ni, nj          !! the spring's nodes
      real(dp), intent(in) :: k              !! its stiffness
      integer, intent(inout) :: ea(:), eb(:) !! the elements' groups
      real(dp), intent(inout) :: ek(:)       !! their stiffness
      integer, intent(inout) :: ne           !! the elements so far
      integer :: ga, gb

      ga = 0; gb = 0
      if (ni > 0) ga = grp(ni)
      if (nj > 0) gb = grp(nj)
      if (ga == gb) return
      ne = ne + 1
      ea(ne) = max(ga, gb); eb(ne) = min(ga, gb); ek(ne) = k
   end subroutine add_element

   !> The rigid groups of a system (link_groups): stuck, every device with P mu > 0 that is
   !> no spring (velocity law, Coulomb) links its nodes; free, none does. modes%nq is their
   !> number; a system with none (every DOF held to the table) is rigid: no mode.
   subroutine system_groups(model, system, grp, modes, stat)
      type(model_type), intent(in) :: model          !! the model
      integer, intent(in) :: system                  !! system_stuck or system_free
      integer, allocatable, intent(out) :: grp(:)    !! group of each DOF, 0 = with the table
      type(modes_type), intent(inout) :: modes       !! its nq; status and arrays if rigid
      integer, intent(out) :: stat                   !! 0, or not enough memory
      logical, allocatable :: linked(:)
      integer :: d

      allocate (grp(model%n_dof), linked(model%n_devices), stat=stat)
      if (stat /= 0) return
      do d = 1, model%n_devices
         linked(d) = system == system_stuck .and. links_when_stuck(model%dev(d))
      end do
      call link_groups(model, linked, grp, modes%nq)
      if (modes%nq == 0) call no_free_dof(model%n_dof, modes)
   end subroutine system_groups

   !> The modes of a system without a free DOF: status modes_rigid, arrays of no mode.
   subroutine no_free_dof(n, modes)
      integer, intent(in) :: n                       !! DOFs
      type(modes_type), intent(inout) :: modes       !! the modes
      modes%status = modes_rigid
      allocate (modes%omega2(0), modes%period(0), modes%shape(n, 0), modes%mass_ratio(0), modes%xi(0))
   end subroutine no_free_dof

   !> store_modes for modes over every DOF (each DOF its own group): status modes_flexible,
   !> or modes_unrestrained with the eigenvalues below 1e-12 big as rigid-body modes.
   subroutine store_dof_modes(model, lam, z, big, zcz, modes, error)
      type(model_type), intent(in) :: model          !! the model
      real(dp), intent(in) :: lam(:)                 !! eigenvalues, ascending
      real(dp), intent(in) :: z(:, :)                !! M-normalized shapes over the DOFs
      real(dp), intent(in) :: big                    !! the spectrum's scale
      real(dp), intent(in) :: zcz(:)                 !! z' C z of the modes kept
      type(modes_type), intent(inout) :: modes       !! the modes (nq, n set)
      type(error_type), allocatable, intent(out) :: error !! no memory
      integer, allocatable :: grp(:)
      integer :: j, n, stat

      n = model%n_dof
      modes%status = modes_flexible
      if (lam(1) <= 1.0e-12_dp*big) modes%status = modes_unrestrained
      allocate (grp(n), stat=stat)
      if (stat == 0) then
         grp = [(j, j=1, n)]
         call store_modes(grp, model%mass, lam, z, lam(1:modes%n) <= 1.0e-12_dp*big, zcz, modes, stat, &
                          model%influence)
      end if
      if (stat /= 0) call out_of_memory('natural modes', n, error)
   end subroutine store_dof_modes

   !> The modes' arrays from the lowest modes%n eigenpairs (lam, z) of the reduced system of
   !> the rigid groups grp (z' Mq z = 1): each shape expanded to every DOF and scaled so
   !> that its component of largest magnitude is +1, its effective mass ratio; a rigid-body
   !> mode (rigid) has w = 0, an infinite period and no damping ratio, the others
   !> w = sqrt(lam) and xi = zcz / (2 w), zcz = z' Cq z.
   subroutine store_modes(grp, mass, lam, z, rigid, zcz, modes, stat, influence)
      integer, intent(in) :: grp(:)                  !! group of each DOF, 0 = with the table
      real(dp), intent(in) :: mass(:)                !! masses of the DOFs
      real(dp), intent(in) :: lam(:)                 !! eigenvalues w^2, increasing
      real(dp), intent(in) :: z(:, :)                !! eigenvectors (nq, >= modes%n)
      logical, intent(in) :: rigid(:)                !! (modes%n) a rigid-body mode
      real(dp), intent(in) :: zcz(:)                 !! (modes%n) z' Cq z
      type(modes_type), intent(inout) :: modes       !! n set; its arrays
      integer, intent(out) :: stat                   !! 0, or not enough memory
      real(dp), intent(in), optional :: influence(:) !! r, the table motion's direction (default 1)
      real(dp), allocatable :: phi(:), mr(:)
      real(dp) :: w, l, mtot
      integer :: n, i, j, imax

      n = size(grp)
      allocate (modes%omega2(modes%n), modes%period(modes%n), modes%shape(n, modes%n), &
                modes%mass_ratio(modes%n), modes%xi(modes%n), phi(n), stat=stat)
      if (stat /= 0) return
      ! the effective mass along r: (phi' M r)^2 / (phi' M phi), of the total r' M r
      mr = mass
      mtot = sum(mass)
      if (present(influence)) then
         mr = mass*influence
         mtot = sum(mr*influence)
      end if
      do j = 1, modes%n
         do i = 1, n
            phi(i) = 0.0_dp
            if (grp(i) /= 0) phi(i) = z(grp(i), j)
         end do
         imax = maxloc(abs(phi), 1)
         phi = phi/phi(imax)
         modes%shape(:, j) = phi
         l = sum(mr*phi)
         modes%mass_ratio(j) = l*l/sum(mass*phi**2)/mtot
         if (rigid(j)) then
            modes%omega2(j) = 0.0_dp
            modes%period(j) = ieee_value(1.0_dp, ieee_positive_inf)
            modes%xi(j) = ieee_value(1.0_dp, ieee_quiet_nan)
         else
            modes%omega2(j) = lam(j)
            w = sqrt(lam(j))
            modes%period(j) = 2.0_dp*pi/w
            modes%xi(j) = zcz(j)/(2.0_dp*w)
         end if
      end do
   end subroutine store_modes

   !> The root of x in a union-find forest (root(x) = x at a root).
   pure integer function find(root, x)
      integer, intent(in) :: root(0:)   !! parent of each node
      integer, intent(in) :: x          !! the node
      find = x
      do while (root(find) /= find)
         find = root(find)
      end do
   end function find

   !> The error of an allocation that failed: "not enough memory for the <what> of <size>
   !> DOFs<note>".
   subroutine out_of_memory(what, size, error, note)
      character(len=*), intent(in) :: what                 !! what the memory was for
      integer, intent(in) :: size                          !! its DOFs
      type(error_type), allocatable, intent(out) :: error  !! the error
      character(len=*), intent(in), optional :: note       !! said after the DOFs

      if (present(note)) then
         call fatal_error(error, "not enough memory for the "//what//" of "//trim(fmt_int(size))//" DOFs"//note, &
                          stat_no_memory)
      else
         call fatal_error(error, "not enough memory for the "//what//" of "//trim(fmt_int(size))//" DOFs", &
                          stat_no_memory)
      end if
   end subroutine out_of_memory

end module fd_matrices
