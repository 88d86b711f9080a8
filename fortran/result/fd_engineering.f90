!> What a design engineer reads from a run, kept by the observer for every technique:
!> the names of the DOFs, devices and storeys; the natural modes with every device stuck
!> and with every device free; the damping actually used (C = a0 M + a1 K); per storey the
!> drift (and drift ratio), the storey shear and their peaks and residual values; the base
!> shear; the residual relative displacement of every device.
!>
!> A storey is a pair of nodes (upper node_i, lower node_j; 0 = the table). Its drift is
!> u(node_i) - u(node_j); its shear is the force carried by every element joining exactly
!> those two nodes: each spring k's elastic force k (drift) and its share b k (drift rate)
!> of the stiffness-proportional damping C = a0 M + b K, and each device's friction force,
!> positive when it resists a positive drift. The base shear is the same sum over every
!> element joined to the table. Mass-proportional damping (a0 M) is carried by no element:
!> with a0 = 0 the base shear equals -sum m_i aabs_i, the inertia forces of the masses.
module fd_engineering
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, stat_no_memory
   use fd_model, only: model_type, integration_type, label_len, system_stuck, system_free, &
                       damping_stiffness, damping_rayleigh, source_floor_brace
   use fd_kinematics, only: pair_nodes, devices_are_pairs, device_relative
   use fd_stiffness, only: stiffness_times, influence_of
   use fd_floors, only: floor_dof
   use fd_excitation, only: excitation_type, excitation_harmonic
   use fd_matrices, only: modes_type, natural_modes, natural_modes_sparse, stiffness_matrix, damping_matrix, &
                          stiffness_damping_factor, modes_dense_dofs
   implicit none
   private

   public :: engineering_type, engineering_init, storey_values, observe_engineering, engineering_columns
   public :: observe_storey_peak, observe_floor_accelerations

   !> The engineering outputs of a run.
   type :: engineering_type
      ! the run
      integer :: excitation = 0                 !! excitation id (fd_names)
      real(dp) :: frequency = 0.0_dp            !! table frequency (harmonic) [Hz]
      real(dp) :: duration = 0.0_dp             !! analysed duration [s]
      ! names
      character(len=label_len), allocatable :: dof_label(:)     !! name of each DOF
      character(len=label_len), allocatable :: device_label(:)  !! name of each device
      character(len=label_len), allocatable :: storey_label(:)  !! name of each storey
      ! damping used, C = a0 M + a1 K
      real(dp) :: a0 = 0.0_dp                   !! mass factor [1/s]
      real(dp) :: a1 = 0.0_dp                   !! stiffness factor [s]
      ! natural modes
      type(modes_type) :: stuck                 !! every device stuck
      type(modes_type) :: free                  !! every device free
      ! storeys; cut 0 is the base (every element joined to the table)
      integer :: n_storeys = 0                  !! storeys
      integer, allocatable :: storey_i(:)       !! upper node
      integer, allocatable :: storey_j(:)       !! lower node (0 = table)
      real(dp), allocatable :: height(:)        !! storey height [m] (0: not given)
      real(dp), allocatable :: r(:)             !! (n_dof) r, when the model gives one [-]
      real(dp), allocatable :: r2(:)            !! (n_dof) r2 of a second component, if any [-]
      ! the force across each cut c (0 = the base, 1..n_storeys) as a sum of terms, those of
      ! cut c at term_first(c):term_first(c+1)-1: the springs joining the cut's two nodes,
      ! then its devices, then its forces beyond those elements. A spring term (term_i,
      ! term_j >= 0: its nodes, 0 the table) adds term_c (du + a1 dv), term_c the stiffness
      ! signed along the cut; a device term (term_i = -d) adds term_c F_d, term_c its sign.
      ! The forces beyond the elements: a storey's rigid floors' frames and braces; the base of
      ! a general model (stiffness K_x, devices of any direction), along the table motion r,
      ! r' (K u + a1 K v) + sum_d (b_d' r) F_d, the forces every element passes to the table
      ! (one inside the structure passes none: b' r = 0), as springs from DOF i to the table
      ! of stiffness (K r)_i and devices of sign b_d' r; its springs and devices are then not
      ! listed
      integer, allocatable :: term_first(:)     !! (0:n_storeys+1)
      integer, allocatable :: term_i(:), term_j(:) !! nodes of a spring; -d for device d
      real(dp), allocatable :: term_c(:)        !! [N/m] (spring) or [-] (device)
      ! a building of rigid floors: the drift of each storey along its axis at the four plan
      ! corners of its floor (a rectangle about the floor's centre of mass), as functionals
      ! corner_coef(t, c, q) u(corner_dof(t, c, q)), t = 1..4; its peak over the corners
      logical, allocatable :: has_corners(:)      !! (n_storeys) the floor's plan is known
      integer, allocatable :: corner_dof(:, :, :) !! (4, 4, n_storeys)
      real(dp), allocatable :: corner_coef(:, :, :) !! (4, 4, n_storeys)
      real(dp), allocatable :: peak_corner(:)     !! (n_storeys) max |drift| over the corners [m]
      real(dp), allocatable :: peak_corner_time(:) !! its time [s]
      ! a building of rigid floors: the forces the elements pass to the table along the rigid
      ! motions t_a of the floors, a = 1 along x, 2 along y, 3 a rotation about the vertical
      ! axis through the plan origin (the base shears and the base torque):
      ! t_a' (K u + a1 K v) + sum_d (b_d' t_a) F_d
      integer :: n_floors = 0                     !! floors (0: no building of rigid floors)
      real(dp), allocatable :: kt(:, :)           !! (n_dof, 3) K t_a [N/m, N]
      real(dp), allocatable :: bt(:, :)           !! (n_devices, 3) b_d' t_a [-, m]
      real(dp) :: base3(3) = 0.0_dp               !! at the last state [N, N, N m]
      real(dp) :: peak_base3(3) = 0.0_dp          !! their peaks [N, N, N m]
      real(dp) :: peak_base3_time(3) = 0.0_dp     !! their times [s]
      ! the effective modal mass along x, y and the floors' rotations (rz) over its total,
      ! (mode, direction), of the stuck and the free system
      real(dp), allocatable :: ratio_stuck(:, :), ratio_free(:, :)
      ! the absolute acceleration at the plan corners of each floor along x and along y: the
      ! largest over the corners is |a_x| + |a_rz| l_y / 2 and |a_y| + |a_rz| l_x / 2
      real(dp), allocatable :: half_plan(:, :)    !! (2, n_floors) l_y / 2, l_x / 2 (0: no plan) [m]
      real(dp), allocatable :: peak_corner_aabs(:, :)      !! (2, n_floors) [m/s2]
      real(dp), allocatable :: peak_corner_aabs_time(:, :) !! (2, n_floors) [s]
      ! the floors' plan, and where each brace of &floor_braces lies in it: its storey (0:
      ! another device), the point of its line nearest its floor's centre of mass, its angle
      real(dp), allocatable :: floor_x(:), floor_y(:), floor_lx(:), floor_ly(:)
      integer, allocatable :: dev_storey(:)       !! (n_devices)
      real(dp), allocatable :: dev_x(:), dev_y(:), dev_angle(:) !! [m, m, deg]
      ! values at the last state observed (the residual values at the end of the run)
      real(dp), allocatable :: drift(:)         !! (n_storeys) drift [m]
      real(dp), allocatable :: shear(:)         !! (0:n_storeys) shear, 0 = base [N]
      real(dp), allocatable :: residual_s(:)    !! (n_devices) device relative displacement [m]
      ! peaks over the accepted states
      real(dp), allocatable :: peak_drift(:)       !! max |drift| [m]
      real(dp), allocatable :: peak_drift_time(:)  !! its time [s]
      real(dp), allocatable :: peak_shear(:)       !! (0:n_storeys) max |shear| [N]
      real(dp), allocatable :: peak_shear_time(:)  !! (0:n_storeys) its time [s]
   end type engineering_type

   !> The elements of every cut, while they are set up (cut c's at first(c):first(c+1)-1 of
   !> each list); join_terms makes them eng's terms.
   type :: cut_lists
      integer, allocatable :: sp_first(:), sp_i(:), sp_j(:) !! springs: their nodes
      real(dp), allocatable :: sp_k(:)                      !! their stiffness, signed along the cut [N/m]
      integer, allocatable :: dv_first(:), dv_id(:)         !! devices
      real(dp), allocatable :: dv_sign(:)                   !! +1 or -1 along the cut
      integer, allocatable :: xs_first(:), xs_dof(:)        !! forces beyond the elements: DOF terms
      real(dp), allocatable :: xs_coef(:)                   !! [N/m]
      integer, allocatable :: xd_first(:), xd_dev(:)        !! and device terms
      real(dp), allocatable :: xd_coef(:)                   !! [-]
   end type cut_lists

contains

   !> Set up the engineering outputs of a run: names (defaults 'DOF i', 'device d', 'storey
   !> s'), the damping used, the modes (opts%n_modes of each system; none when 0), and the
   !> elements of each storey and of the base. `period` is the stuck first period the
   !> technique computed (structure_matrices), which the paper's damping C = psi K uses.
   subroutine engineering_init(model, exc, opts, period, eng, error)
      type(model_type), intent(in) :: model         !! the model run
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(integration_type), intent(in) :: opts    !! n_modes
      real(dp), intent(in) :: period                !! stuck first period [s] (0: none)
      type(engineering_type), intent(out) :: eng    !! the outputs, set up
      type(error_type), allocatable, intent(out) :: error !! eigenvalue solver failure
      real(dp), allocatable :: k(:, :), c(:, :)
      type(cut_lists) :: cuts
      integer :: n, nd, ns, i, s, stat
      logical :: general

      n = model%n_dof
      nd = model%n_devices
      ns = model%n_storeys
      eng%excitation = exc%kind
      eng%duration = exc%duration
      if (exc%kind == excitation_harmonic) eng%frequency = exc%frequency
      allocate (eng%dof_label(n), eng%device_label(nd), stat=stat)
      if (stat /= 0) then
         call no_memory('the labels'); return
      end if
      do i = 1, n
         eng%dof_label(i) = 'DOF '//trim(fmt_int(i))
         if (allocated(model%dof_label)) then
            if (len_trim(model%dof_label(i)) > 0) eng%dof_label(i) = model%dof_label(i)
         end if
      end do
      do i = 1, nd
         eng%device_label(i) = model%dev(i)%label
         if (len_trim(eng%device_label(i)) == 0) eng%device_label(i) = 'device '//trim(fmt_int(i))
      end do
      ! C = a0 M + a1 K
      select case (model%damping)
      case (damping_stiffness)
         eng%a1 = stiffness_damping_factor(model, period)
      case (damping_rayleigh)
         eng%a0 = model%rayleigh_a0
         eng%a1 = model%rayleigh_a1
      end select
      ! natural modes
      if (opts%n_modes > 0 .and. n > modes_dense_dofs) then
         ! a large model: no n x n matrix (fd_modes' subspace iteration on the elements)
         call natural_modes_sparse(model, eng%a0, eng%a1, system_stuck, opts%n_modes, eng%stuck, error)
         if (allocated(error)) return
         call natural_modes_sparse(model, eng%a0, eng%a1, system_free, opts%n_modes, eng%free, error)
         if (allocated(error)) return
      else if (opts%n_modes > 0) then
         allocate (k(n, n), c(n, n), stat=stat)
         if (stat /= 0) then
            call no_memory('the modes (two '//trim(fmt_int(n))//' x '//trim(fmt_int(n))//' matrices)'); return
         end if
         call stiffness_matrix(model, k)
         call damping_matrix(model, k, merge(model%period, period, model%period > 0.0_dp), c)
         call natural_modes(model, k, c, system_stuck, opts%n_modes, eng%stuck, error)
         if (allocated(error)) return
         call natural_modes(model, k, c, system_free, opts%n_modes, eng%free, error)
         if (allocated(error)) return
      end if
      ! storeys and their elements
      eng%n_storeys = ns
      allocate (eng%storey_i(ns), eng%storey_j(ns), eng%height(ns), eng%storey_label(ns), stat=stat)
      if (stat /= 0) then
         call no_memory('the storeys'); return
      end if
      do s = 1, ns
         eng%storey_i(s) = model%storey_i(s)
         eng%storey_j(s) = model%storey_j(s)
         eng%height(s) = model%storey_height(s)
         eng%storey_label(s) = 'storey '//trim(fmt_int(s))
         if (allocated(model%storey_label)) then
            if (len_trim(model%storey_label(s)) > 0) eng%storey_label(s) = model%storey_label(s)
         end if
      end do
      if (allocated(model%influence)) eng%r = model%influence
      if (allocated(model%influence2)) eng%r2 = model%influence2
      general = model%n_kx > 0 .or. .not. devices_are_pairs(model)
      call storey_elements(model, eng, general, cuts, stat)
      if (stat == 0 .and. (general .or. allocated(model%xs_storey))) call cut_extras(model, ns, general, cuts, stat)
      if (stat == 0) call join_terms(cuts, ns, eng, stat)
      if (stat == 0 .and. model%n_floors > 0) call floor_corners(model, eng, stat)
      if (stat == 0 .and. model%n_floors > 0) call floor_outputs(model, eng, stat)
      if (stat /= 0) then
         call no_memory('the elements of the storeys'); return
      end if
      allocate (eng%drift(ns), eng%shear(0:ns), eng%residual_s(nd), eng%peak_drift(ns), &
                eng%peak_drift_time(ns), eng%peak_shear(0:ns), eng%peak_shear_time(0:ns), stat=stat)
      if (stat /= 0) then
         call no_memory('the storeys'); return
      end if
      eng%drift = 0.0_dp; eng%shear = 0.0_dp; eng%residual_s = 0.0_dp
      eng%peak_drift = 0.0_dp; eng%peak_drift_time = 0.0_dp
      eng%peak_shear = 0.0_dp; eng%peak_shear_time = 0.0_dp
   contains
      subroutine no_memory(what)
         character(len=*), intent(in) :: what
         call fatal_error(error, "not enough memory for the engineering outputs of "//trim(fmt_int(n))// &
                          " DOFs, "//trim(fmt_int(nd))//" devices and "//trim(fmt_int(ns))//" storeys: "//what, &
                          stat_no_memory)
      end subroutine no_memory
   end subroutine engineering_init

   !> The springs and devices of every cut (0 = the base, 1..n_storeys the storeys), with
   !> their sign along the cut, in compressed lists (none at the base of a general model,
   !> whose base is cut_extras').
   subroutine storey_elements(model, eng, general, cuts, stat)
      type(model_type), intent(in) :: model
      type(engineering_type), intent(in) :: eng    !! its storeys
      logical, intent(in) :: general               !! a general model
      type(cut_lists), intent(inout) :: cuts       !! the cuts' springs and devices, set
      integer, intent(out) :: stat                 !! not 0: not enough memory
      integer :: ns, cut, e, a, b, nsp, ndv
      real(dp) :: sgn

      ns = eng%n_storeys
      allocate (cuts%sp_first(0:ns + 1), cuts%dv_first(0:ns + 1), stat=stat)
      if (stat /= 0) return
      ! count, then fill
      nsp = 0; ndv = 0
      do cut = 0, ns
         do e = 1, model%n_springs
            if (on_cut(cut, model%spring_i(e), model%spring_j(e)) /= 0.0_dp) nsp = nsp + 1
         end do
         do e = 1, model%n_devices
            call pair_nodes(model, e, a, b)
            if (a == 0) cycle
            if (on_cut(cut, a, b) /= 0.0_dp) ndv = ndv + 1
         end do
      end do
      allocate (cuts%sp_i(nsp), cuts%sp_j(nsp), cuts%sp_k(nsp), cuts%dv_id(ndv), cuts%dv_sign(ndv), stat=stat)
      if (stat /= 0) return
      nsp = 0; ndv = 0
      do cut = 0, ns
         cuts%sp_first(cut) = nsp + 1
         cuts%dv_first(cut) = ndv + 1
         do e = 1, model%n_springs
            a = model%spring_i(e); b = model%spring_j(e)
            sgn = on_cut(cut, a, b)
            if (sgn == 0.0_dp) cycle
            nsp = nsp + 1
            cuts%sp_i(nsp) = a; cuts%sp_j(nsp) = b; cuts%sp_k(nsp) = sgn*model%spring_k(e)
         end do
         do e = 1, model%n_devices
            call pair_nodes(model, e, a, b)
            if (a == 0) cycle
            sgn = on_cut(cut, a, b)
            if (sgn == 0.0_dp) cycle
            ndv = ndv + 1
            cuts%dv_id(ndv) = e; cuts%dv_sign(ndv) = sgn
         end do
      end do
      cuts%sp_first(ns + 1) = nsp + 1
      cuts%dv_first(ns + 1) = ndv + 1
   contains
      !> +1 if the element (a, b) lies on the cut in its direction, -1 reversed, 0 not on it.
      real(dp) function on_cut(cut, a, b) result(sgn)
         integer, intent(in) :: cut, a, b
         sgn = 0.0_dp
         if (cut == 0) then
            if (general) return
            if (b == 0) sgn = 1.0_dp
            if (a == 0) sgn = -1.0_dp
         else if (a == eng%storey_i(cut) .and. b == eng%storey_j(cut)) then
            sgn = 1.0_dp
         else if (a == eng%storey_j(cut) .and. b == eng%storey_i(cut)) then
            sgn = -1.0_dp
         end if
      end function on_cut
   end subroutine storey_elements

   !> The forces the elements pass to the table along a motion t of the DOFs: K t (the
   !> springs' and K_x's) and b_d' t of every device.
   pure subroutine base_along(model, t, kt, bt)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: t(:)                 !! (n_dof) the motion
      real(dp), intent(out) :: kt(:)               !! (n_dof) K t
      real(dp), intent(out) :: bt(:)               !! (n_devices) b_d' t
      integer :: d

      call stiffness_times(model, t, kt)
      do d = 1, model%n_devices
         bt(d) = device_relative(model, d, t)
      end do
   end subroutine base_along

   !> Drift and shear of every storey, and the base shear, at one state.
   pure subroutine storey_values(eng, u, v, force, drift, shear, base)
      type(engineering_type), intent(in) :: eng  !! the set-up outputs
      real(dp), intent(in) :: u(:)               !! relative displacements [m]
      real(dp), intent(in) :: v(:)               !! relative velocities [m/s]
      real(dp), intent(in) :: force(:)           !! device forces [N]
      real(dp), intent(out) :: drift(:)          !! (n_storeys) drift [m]
      real(dp), intent(out) :: shear(:)          !! (n_storeys) storey shear [N]
      real(dp), intent(out) :: base              !! base shear [N]
      real(dp) :: f
      integer :: s

      ! the base (cut 0) and every storey in one loop: one call of cut_force here, which the
      ! per-step observer's inlining of it asks
      do s = 0, eng%n_storeys
         f = cut_force(eng, s, u, v, force)
         if (s == 0) then
            base = f
         else
            drift(s) = storey_drift(eng, s, u)
            shear(s) = f
         end if
      end do
   end subroutine storey_values

   !> Drift of storey s, u(node_i) - u(node_j) (node 0: the table).
   pure real(dp) function storey_drift(eng, s, u) result(du)
      type(engineering_type), intent(in) :: eng  !! the set-up outputs
      integer, intent(in) :: s                   !! storey
      real(dp), intent(in) :: u(:)               !! relative displacements [m]
      integer :: i, j

      i = eng%storey_i(s)
      j = eng%storey_j(s)
      du = 0.0_dp
      if (i > 0) du = u(i)
      if (j > 0) du = du - u(j)
   end function storey_drift

   !> The force across cut `cut` (0: the base): the sum of its terms (the springs' elastic
   !> and stiffness-damping forces, the devices', the forces beyond its elements), in one loop
   !> over one list: the per-step observer runs it for every cut.
   pure real(dp) function cut_force(eng, cut, u, v, force) result(f)
      type(engineering_type), intent(in) :: eng  !! the set-up outputs
      integer, intent(in) :: cut                 !! 0 (base) .. n_storeys
      ! (assumed sizes: a call that builds three array descriptors costs a two-mass model more
      ! than its base's two springs)
      real(dp), intent(in) :: u(*)               !! relative displacements [m]
      real(dp), intent(in) :: v(*)               !! relative velocities [m/s]
      real(dp), intent(in) :: force(*)           !! device forces [N]
      real(dp) :: du, dv
      integer :: e, i, j

      f = 0.0_dp
      do e = eng%term_first(cut), eng%term_first(cut + 1) - 1
         i = eng%term_i(e)
         if (i < 0) then
            f = f + eng%term_c(e)*force(-i)
         else
            j = eng%term_j(e)
            du = 0.0_dp
            dv = 0.0_dp
            if (i > 0) then
               du = u(i)
               dv = v(i)
            end if
            if (j > 0) then
               du = du - u(j)
               dv = dv - v(j)
            end if
            f = f + eng%term_c(e)*(du + eng%a1*dv)
         end if
      end do
   end function cut_force

   !> eng's terms of every cut from the cuts' lists: springs, devices, then the forces beyond
   !> the elements (a DOF term as a spring from the DOF to the table, a device term as a device).
   subroutine join_terms(cuts, ns, eng, stat)
      type(cut_lists), intent(in) :: cuts
      integer, intent(in) :: ns                    !! storeys
      type(engineering_type), intent(inout) :: eng
      integer, intent(out) :: stat                 !! not 0: not enough memory
      integer :: c, e, m
      logical :: extra

      extra = allocated(cuts%xs_first)
      m = size(cuts%sp_i) + size(cuts%dv_id)
      if (extra) m = m + size(cuts%xs_dof) + size(cuts%xd_dev)
      allocate (eng%term_first(0:ns + 1), eng%term_i(m), eng%term_j(m), eng%term_c(m), stat=stat)
      if (stat /= 0) return
      m = 0
      do c = 0, ns
         eng%term_first(c) = m + 1
         do e = cuts%sp_first(c), cuts%sp_first(c + 1) - 1
            call add(cuts%sp_i(e), cuts%sp_j(e), cuts%sp_k(e))
         end do
         do e = cuts%dv_first(c), cuts%dv_first(c + 1) - 1
            call add(-cuts%dv_id(e), 0, cuts%dv_sign(e))
         end do
         if (.not. extra) cycle
         do e = cuts%xs_first(c), cuts%xs_first(c + 1) - 1
            call add(cuts%xs_dof(e), 0, cuts%xs_coef(e))
         end do
         do e = cuts%xd_first(c), cuts%xd_first(c + 1) - 1
            call add(-cuts%xd_dev(e), 0, cuts%xd_coef(e))
         end do
      end do
      eng%term_first(ns + 1) = m + 1
   contains
      subroutine add(i, j, coef)
         integer, intent(in) :: i, j
         real(dp), intent(in) :: coef
         m = m + 1
         eng%term_i(m) = i; eng%term_j(m) = j; eng%term_c(m) = coef
      end subroutine add
   end subroutine join_terms

   !> The cut forces beyond the cuts' elements (xs_*, xd_*), by cut: the base's of a general
   !> model (general: K r and b_d' r, r the table motion's direction), then the model's storey
   !> forces beyond its storeys' elements.
   subroutine cut_extras(model, ns, general, cuts, stat)
      type(model_type), intent(in) :: model
      integer, intent(in) :: ns                    !! storeys
      logical, intent(in) :: general               !! a general model
      type(cut_lists), intent(inout) :: cuts       !! the cuts' forces beyond their elements, set
      integer, intent(out) :: stat                 !! not 0: not enough memory
      real(dp), allocatable :: r(:), kr(:), br(:)
      integer :: i, n, nd

      n = 0
      nd = 0
      if (general) then
         n = model%n_dof
         nd = model%n_devices
      end if
      allocate (r(model%n_dof), kr(n), br(nd), stat=stat)
      if (stat /= 0) return
      if (general) then
         do i = 1, n
            r(i) = influence_of(model, i)
         end do
         call base_along(model, r, kr, br)
      end if
      if (allocated(model%xs_storey)) then
         call by_cut(ns, model%xs_storey, model%xs_dof, model%xs_coef, kr, cuts%xs_first, cuts%xs_dof, &
                     cuts%xs_coef, stat)
         if (stat == 0) call by_cut(ns, model%xd_storey, model%xd_dev, model%xd_coef, br, cuts%xd_first, &
                                    cuts%xd_dev, cuts%xd_coef, stat)
      else
         call by_cut(ns, [integer ::], [integer ::], [real(dp) ::], kr, cuts%xs_first, cuts%xs_dof, &
                     cuts%xs_coef, stat)
         if (stat == 0) call by_cut(ns, [integer ::], [integer ::], [real(dp) ::], br, cuts%xd_first, &
                                    cuts%xd_dev, cuts%xd_coef, stat)
      end if
   end subroutine cut_extras

   !> Entries by cut: the base's coefficients base(1:nb) of indices 1..nb at first(0):first(1)-1
   !> of idx and coef, then the storeys' (storey, index, coefficient) sorted by storey, those
   !> of storey c at first(c):first(c+1)-1.
   pure subroutine by_cut(ns, storey, index, coefficient, base, first, idx, coef, stat)
      integer, intent(in) :: ns, storey(:), index(:)
      real(dp), intent(in) :: coefficient(:), base(:)
      integer, allocatable, intent(out) :: first(:), idx(:)
      real(dp), allocatable, intent(out) :: coef(:)
      integer, intent(out) :: stat
      integer :: c, e, k

      allocate (first(0:ns + 1), idx(size(base) + size(storey)), coef(size(base) + size(storey)), stat=stat)
      if (stat /= 0) return
      first(0) = 1
      do k = 1, size(base)
         idx(k) = k; coef(k) = base(k)
      end do
      k = size(base)
      do c = 1, ns
         first(c) = k + 1
         do e = 1, size(storey)
            if (storey(e) /= c) cycle
            k = k + 1
            idx(k) = index(e); coef(k) = coefficient(e)
         end do
      end do
      first(ns + 1) = k + 1
   end subroutine by_cut

   !> One accepted state: drifts and shears, their peaks, and the values kept as the
   !> residual ones (those of the last state observed; the devices' residual displacements
   !> are the observer's, kept with their peaks); a building of rigid floors, its base shears
   !> along x, y and the base torque (kt, bt), and each storey's largest corner drift. Runs at
   !> every accepted step: the values go straight into the peaks (no array sections passed,
   !> no temporaries).
   pure subroutine observe_engineering(eng, t, n, nd, u, v, force)
      type(engineering_type), intent(inout) :: eng  !! the outputs
      real(dp), intent(in) :: t                     !! time [s]
      integer, intent(in) :: n                      !! DOFs
      integer, intent(in) :: nd                     !! devices
      real(dp), intent(in) :: u(n)                  !! relative displacements [m]
      real(dp), intent(in) :: v(n)                  !! relative velocities [m/s]
      real(dp), intent(in) :: force(nd)             !! device forces [N]
      real(dp) :: x
      integer :: i, c, k

      if (.not. allocated(eng%drift)) return
      do i = 1, eng%n_storeys
         call track(storey_drift(eng, i, u), t, eng%drift(i), eng%peak_drift(i), eng%peak_drift_time(i))
      end do
      do i = 0, eng%n_storeys
         call track(cut_force(eng, i, u, v, force), t, eng%shear(i), eng%peak_shear(i), eng%peak_shear_time(i))
      end do
      ! a building of rigid floors (kt, bt and the corners are set up with its floors)
      if (eng%n_floors == 0) return
      do c = 1, 3
         x = 0.0_dp
         do i = 1, n
            x = x + eng%kt(i, c)*(u(i) + eng%a1*v(i))
         end do
         do i = 1, nd
            x = x + eng%bt(i, c)*force(i)
         end do
         call track(x, t, eng%base3(c), eng%peak_base3(c), eng%peak_base3_time(c))
      end do
      do i = 1, eng%n_storeys
         if (.not. eng%has_corners(i)) cycle
         do c = 1, 4
            ! term by term: a vector subscript of u would make a temporary at every step
            x = 0.0_dp
            do k = 1, 4
               x = x + eng%corner_coef(k, c, i)*u(eng%corner_dof(k, c, i))
            end do
            call peak_at(abs(x), t, eng%peak_corner(i), eng%peak_corner_time(i))
         end do
      end do
   end subroutine observe_engineering

   !> A quantity's value x at the accepted time t: kept as its last value, and its magnitude
   !> into its peak (and the peak's time) when it exceeds it.
   pure subroutine track(x, t, last, peak, peak_time)
      real(dp), intent(in) :: x                     !! the value
      real(dp), intent(in) :: t                     !! its time [s]
      real(dp), intent(out) :: last                 !! the last value
      real(dp), intent(inout) :: peak               !! the peak |x| so far
      real(dp), intent(inout) :: peak_time          !! its time [s]

      last = x
      call peak_at(abs(x), t, peak, peak_time)
   end subroutine track

   !> A magnitude y >= 0 at time t into a peak (and the peak's time) when it exceeds it.
   pure subroutine peak_at(y, t, peak, peak_time)
      real(dp), intent(in) :: y                     !! the magnitude
      real(dp), intent(in) :: t                     !! its time [s]
      real(dp), intent(inout) :: peak               !! the peak so far
      real(dp), intent(inout) :: peak_time          !! its time [s]

      if (y > peak) then
         peak = y; peak_time = t
      end if
   end subroutine peak_at

   !> The plan corners of a building of rigid floors: storey q = 2 s - 2 + a (a = 1 along x,
   !> 2 along y) at the corners (x_s +- l_x / 2, y_s +- l_y / 2) of floor s: the motion of
   !> the corner P along a on floor s, ux - rz (y_P - y_s) (uy + rz (x_P - x_s)), minus the
   !> same point's on floor s - 1 (none on the ground). Unused terms point at DOF 1 with 0.
   subroutine floor_corners(model, eng, stat)
      type(model_type), intent(in) :: model
      type(engineering_type), intent(inout) :: eng
      integer, intent(out) :: stat                 !! not 0: not enough memory
      real(dp) :: px, py, arm
      integer :: ns, q, s, a, c, f, k, t

      ns = eng%n_storeys
      allocate (eng%has_corners(ns), eng%corner_dof(4, 4, ns), eng%corner_coef(4, 4, ns), eng%peak_corner(ns), &
                eng%peak_corner_time(ns), stat=stat)
      if (stat /= 0) return
      eng%corner_dof = 1
      eng%corner_coef = 0.0_dp
      eng%peak_corner = 0.0_dp
      eng%peak_corner_time = 0.0_dp
      do q = 1, ns
         s = (q + 1)/2
         a = q - 2*(s - 1)
         eng%has_corners(q) = model%floor_lx(s) > 0.0_dp .and. model%floor_ly(s) > 0.0_dp
         if (.not. eng%has_corners(q)) cycle
         do c = 1, 4
            px = model%floor_x(s) + merge(0.5_dp, -0.5_dp, c == 1 .or. c == 4)*model%floor_lx(s)
            py = model%floor_y(s) + merge(0.5_dp, -0.5_dp, c <= 2)*model%floor_ly(s)
            t = 0
            do k = 0, 1
               f = s - k
               if (f < 1) exit
               if (a == 1) then
                  arm = -(py - model%floor_y(f))
               else
                  arm = px - model%floor_x(f)
               end if
               t = t + 1
               eng%corner_dof(t, c, q) = floor_dof(f, a)
               eng%corner_coef(t, c, q) = merge(1.0_dp, -1.0_dp, k == 0)
               t = t + 1
               eng%corner_dof(t, c, q) = floor_dof(f, 3)
               eng%corner_coef(t, c, q) = merge(1.0_dp, -1.0_dp, k == 0)*arm
            end do
         end do
      end do
   end subroutine floor_corners

   !> A building of rigid floors: the rigid motions of the base shears along x and y and of
   !> the base torque about the plan origin, the modal mass ratios along x, y and rz, the
   !> floors' plan and the plan position of each brace of &floor_braces.
   subroutine floor_outputs(model, eng, stat)
      type(model_type), intent(in) :: model
      type(engineering_type), intent(inout) :: eng
      integer, intent(out) :: stat                 !! not 0: not enough memory
      real(dp), allocatable :: t(:), kt(:), bt(:)
      integer :: nf, n, nd, f, a

      nf = model%n_floors
      n = model%n_dof
      nd = model%n_devices
      eng%n_floors = nf
      allocate (t(n), kt(n), bt(nd), eng%kt(n, 3), eng%bt(nd, 3), eng%half_plan(2, nf), &
                eng%peak_corner_aabs(2, nf), eng%peak_corner_aabs_time(2, nf), stat=stat)
      if (stat /= 0) return
      do a = 1, 3
         t = 0.0_dp
         do f = 1, nf
            if (a < 3) then
               t(floor_dof(f, a)) = 1.0_dp
            else
               ! a rotation rz = 1 about the origin moves the centre of mass by (-y_f, x_f)
               t(floor_dof(f, 1)) = -model%floor_y(f)
               t(floor_dof(f, 2)) = model%floor_x(f)
               t(floor_dof(f, 3)) = 1.0_dp
            end if
         end do
         call base_along(model, t, kt, bt)
         eng%kt(:, a) = kt
         eng%bt(:, a) = bt
      end do
      eng%half_plan(1, :) = 0.5_dp*model%floor_ly
      eng%half_plan(2, :) = 0.5_dp*model%floor_lx
      eng%peak_corner_aabs = 0.0_dp
      eng%peak_corner_aabs_time = 0.0_dp
      call direction_ratios(model, eng%stuck, eng%ratio_stuck, stat)
      if (stat == 0) call direction_ratios(model, eng%free, eng%ratio_free, stat)
      if (stat == 0) call brace_plan(model, eng, stat)
   end subroutine floor_outputs

   !> The effective modal mass of each mode along x, y and rz (every floor's DOF of that
   !> component 1, the others 0), (phi' M t)^2 / (phi' M phi), over the total t' M t.
   subroutine direction_ratios(model, modes, ratio, stat)
      type(model_type), intent(in) :: model
      type(modes_type), intent(in) :: modes
      real(dp), allocatable, intent(out) :: ratio(:, :)   !! (modes%n, 3)
      integer, intent(out) :: stat                 !! not 0: not enough memory
      real(dp) :: l, total
      integer :: j, a, f, i

      allocate (ratio(modes%n, 3), stat=stat)
      if (stat /= 0) return
      do a = 1, 3
         total = 0.0_dp
         do f = 1, model%n_floors
            total = total + model%mass(floor_dof(f, a))
         end do
         do j = 1, modes%n
            l = 0.0_dp
            do f = 1, model%n_floors
               i = floor_dof(f, a)
               l = l + model%mass(i)*modes%shape(i, j)
            end do
            ratio(j, a) = l*l/sum(model%mass*modes%shape(:, j)**2)/total
         end do
      end do
   end subroutine direction_ratios

   !> The floors' plan and, for each brace of &floor_braces (direction b of terms c, s and
   !> sin a (x - x_f) - cos a (y - y_f) at the ux, uy, rz of its floor f), its storey, angle
   !> and the point of its line nearest the centre of mass: (x_f, y_f) + d (sin a, -cos a).
   subroutine brace_plan(model, eng, stat)
      type(model_type), intent(in) :: model
      type(engineering_type), intent(inout) :: eng
      integer, intent(out) :: stat                 !! not 0: not enough memory
      real(dp), allocatable :: e(:)
      real(dp) :: b(3)
      integer :: nd, d, k, f, c

      nd = model%n_devices
      allocate (eng%floor_x, source=model%floor_x, stat=stat)
      if (stat == 0) allocate (eng%floor_y, source=model%floor_y, stat=stat)
      if (stat == 0) allocate (eng%floor_lx, source=model%floor_lx, stat=stat)
      if (stat == 0) allocate (eng%floor_ly, source=model%floor_ly, stat=stat)
      if (stat == 0) allocate (eng%dev_storey(nd), eng%dev_x(nd), eng%dev_y(nd), eng%dev_angle(nd), &
                               e(model%n_dof), stat=stat)
      if (stat /= 0) return
      eng%dev_storey = 0
      eng%dev_x = 0.0_dp; eng%dev_y = 0.0_dp; eng%dev_angle = 0.0_dp
      e = 0.0_dp
      if (.not. allocated(model%xd_dev)) return
      do k = 1, size(model%xd_dev)
         d = model%xd_dev(k)
         if (model%dev(d)%source /= source_floor_brace .or. eng%dev_storey(d) /= 0) cycle
         f = (model%xd_storey(k) + 1)/2
         do c = 1, 3
            e(floor_dof(f, c)) = 1.0_dp
            b(c) = device_relative(model, d, e)
            e(floor_dof(f, c)) = 0.0_dp
         end do
         eng%dev_storey(d) = f
         eng%dev_angle(d) = atan2(b(2), b(1))*180.0_dp/acos(-1.0_dp)
         eng%dev_x(d) = model%floor_x(f) + b(3)*b(2)
         eng%dev_y(d) = model%floor_y(f) - b(3)*b(1)
      end do
   end subroutine brace_plan

   !> The absolute accelerations at the floors' plan corners at one accepted state: along x
   !> the largest over the corners |a_x| + |a_rz| l_y / 2, along y |a_y| + |a_rz| l_x / 2
   !> (a the relative acceleration plus the table's along each DOF's r and r2).
   pure subroutine observe_floor_accelerations(eng, t, n, acc, ag, ag2)
      type(engineering_type), intent(inout) :: eng  !! the outputs
      real(dp), intent(in) :: t                     !! time [s]
      integer, intent(in) :: n                      !! DOFs
      real(dp), intent(in) :: acc(n)                !! relative accelerations [m/s2]
      real(dp), intent(in) :: ag                    !! table acceleration [m/s2]
      real(dp), intent(in), optional :: ag2         !! a second component's [m/s2]
      real(dp) :: a(3)
      integer :: f, c, i

      if (.not. allocated(eng%peak_corner_aabs)) return
      do f = 1, eng%n_floors
         do c = 1, 3
            i = floor_dof(f, c)
            a(c) = acc(i)
            if (allocated(eng%r)) a(c) = a(c) + eng%r(i)*ag
            if (present(ag2) .and. allocated(eng%r2)) a(c) = a(c) + eng%r2(i)*ag2
         end do
         do c = 1, 2
            if (eng%half_plan(c, f) <= 0.0_dp) cycle
            call peak_at(abs(a(c)) + abs(a(3))*eng%half_plan(c, f), t, eng%peak_corner_aabs(c, f), &
                         eng%peak_corner_aabs_time(c, f))
         end do
      end do
   end subroutine observe_floor_accelerations

   !> One value into a peak of the storeys (a technique that knows its solution between
   !> steps passes the exact extrema, with their times): q numbers the storey quantities in
   !> the order of the history columns, drift1, V1, drift2, V2, ..., Vb.
   pure subroutine observe_storey_peak(eng, q, value, t)
      type(engineering_type), intent(inout) :: eng  !! the outputs
      integer, intent(in) :: q                      !! storey quantity, 1 .. 2 n_storeys + 1
      real(dp), intent(in) :: value                 !! |value|
      real(dp), intent(in) :: t                     !! its time [s]
      integer :: s

      if (.not. allocated(eng%drift)) return
      if (q == 2*eng%n_storeys + 1) then
         s = 0
      else
         s = (q + 1)/2
         if (mod(q, 2) == 1) then
            call peak_at(value, t, eng%peak_drift(s), eng%peak_drift_time(s))
            return
         end if
      end if
      call peak_at(value, t, eng%peak_shear(s), eng%peak_shear_time(s))
   end subroutine observe_storey_peak

   !> Number of history columns the storeys add: drift and shear per storey and the base
   !> shear, when the model names storeys; none otherwise.
   pure integer function engineering_columns(model) result(ncol)
      type(model_type), intent(in) :: model  !! the model

      ncol = 0
      if (model%n_storeys > 0) ncol = 2*model%n_storeys + 1
   end function engineering_columns

end module fd_engineering
