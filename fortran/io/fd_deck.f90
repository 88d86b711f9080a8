!> The deck reader: one namelist deck is one run. Groups &model, &springs, &damping and
!> &excitation are required; &friction, &integration and &output are optional. Every value
!> is validated after reading (what the technique chosen can integrate is the technique's to
!> say: fd_technique's check_technique, which the session asks after reading); messages name
!> the file, the group, the variable and the value. Keywords, their lists in messages and
!> every default come from fd_names. docs/namelist.md documents every variable.
module fd_deck
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use, intrinsic :: ieee_exceptions, only: ieee_set_halting_mode, ieee_get_halting_mode, ieee_support_halting, &
                                            ieee_overflow, &
                                            ieee_set_flag
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real, fmt_text, stat_no_memory
   use fd_textio, only: lower
   use fd_namelist, only: deck_text, group_text, deck_from_string, find_group, &
                          next_read, check_groups, longest_string, given_elements
   use fd_names, only: keyword_type, keyword_id, keyword_choices, law_id, law_choices, &
                       damping_types, damping_stiffness, damping_rayleigh, damping_none, damping_modal, &
                       excitation_types, excitation_harmonic, excitation_record, excitation_none, &
                       record_kinds, record_displacement, techniques, technique_name, &
                       default_u0, default_v0, default_xi, default_period, default_rayleigh_a0, &
                       default_rayleigh_a1, default_n_devices, default_eps, default_eps1, default_f, &
                       default_ramp_cycles, default_record_kind, default_record_scale, default_technique, &
                       default_beta, default_gamma, default_n1, default_n2, default_n, default_theta, &
                       default_check_correctness, default_dt_min, default_dir, default_output_every, &
                       default_write_history, default_max_history_mb, linear_systems, default_linear_system, &
                       refinements, default_refinement
   use fd_model, only: model_type, integration_type, device_type, output_type
   use fd_kinematics, only: set_pair_directions, append_device
   use fd_excitation, only: excitation_type
   use fd_record, only: read_record, record_info, record_formats, record_units_list, units_factor
   use fd_names, only: label_len, max_mu_points, mu_laws, mu_constant, mu_exponential, mu_table, mode_systems, &
                       system_stuck, law_hysteretic, law_velocity, law_coulomb, &
                       default_mu_law, default_mode_system, default_n_modes, default_radius, default_modal_modes, &
                       default_storey_height, law_name
   use fd_model, only: source_friction, source_brace, source_isolator, source_floor_brace, source_bearing
   use fd_floors, only: floor_dof, plan_direction, floor_inertia, max_plan_terms
   use fd_stiffness, only: add_general_entry
   use fd_matrix_market, only: sparse_matrix, read_matrix_market
   use fd_linalg, only: cholesky_factor
   use fd_friction, only: law_mu_of_speed
   use fd_overturning, only: overturning_arms
   use fd_matrices, only: modes_type, natural_modes, natural_modes_sparse, stiffness_matrix, modes_dense_dofs, &
                          stiffness_pivot
   use fd_modal_damping, only: modal_damping_basis
   use fd_sha256, only: sha256_text
   use fd_textio, only: read_file_text, cr_line_ends
   use fd_result, only: history_shape
   implicit none
   private

   public :: run_config, read_deck, read_deck_string, max_dof, max_springs, max_devices

   ! Largest counts a deck may declare. The arrays read are sized from the deck's own counts
   ! (array_capacity), so these only bound what a deck may ask: about 1.3 kB of memory a DOF
   ! (the effective stiffness of every step size, docs/namelist.md), 1.3 GB at the limit.
   integer, parameter :: max_dof = 1000000      !! DOFs (n_dof)
   integer, parameter :: max_springs = 4000000  !! springs (n_springs)
   integer, parameter :: max_devices = 1000000  !! friction devices (n_devices)
   integer, parameter :: max_floors = max_dof/3 !! rigid floors (n_floors), three DOFs each
   !> Most DOFs of &matrices whose K is checked as a dense matrix (symmetry of a 'general'
   !> file): 3000 DOFs, 72 MB
   integer, parameter :: max_dense_check = 3000
   !> What the variables read hold before the read: a filler only. Whether the deck gives a
   !> value is read from its text (given_elements), never from a value: any value a deck can
   !> write, this one too, is a value given.
   real(dp), parameter :: unset = -huge(1.0_dp)
   !> Largest magnitude of a real value, and smallest of a value that must be > 0 (a mass,
   !> stiffness, band, step, frequency...): within them the products a run forms (forces,
   !> energies, effective stiffness) stay far from the limits of double precision.
   real(dp), parameter, public :: max_magnitude = 1.0e30_dp, min_scale = 1.0e-30_dp
   integer, parameter :: unset_int = -huge(1)
   integer, parameter :: name_len = 32        !! capacity of a keyword value
   integer, parameter :: path_len = 1024      !! capacity of record_file, dir, name

   !> Everything one deck defines.
   type :: run_config
      character(len=:), allocatable :: deck_path  !! the deck read
      type(model_type) :: model                   !! structure and devices
      type(excitation_type) :: exc                !! table motion
      type(integration_type) :: opts              !! integration settings
      type(output_type) :: out                    !! output settings
      type(record_info) :: record                 !! the record read (excitation_type = 'record')
      type(excitation_type) :: exc2               !! the second horizontal component (kind none: not given)
      type(record_info) :: record2                !! its record
      type(excitation_type) :: exc3               !! the vertical component (kind none: not given)
      type(record_info) :: record3                !! its record
   end type run_config

   !> The checks of a group's values, by the group's name and the elements given
   !> (the *_named forms), or by the group's text (its name and the elements it gives).
   interface need_int
      module procedure need_int_named, need_int_of
   end interface need_int
   interface need_reals
      module procedure need_reals_named, need_reals_of
   end interface need_reals
   interface optional_reals
      module procedure optional_reals_named, optional_reals_of
   end interface optional_reals
   interface signed_reals
      module procedure signed_reals_named, signed_reals_of
   end interface signed_reals
   interface node_list
      module procedure node_list_named, node_list_of
   end interface node_list

contains

   !> Read and validate a deck file. Its bytes are read once: split into lines as load_deck
   !> does, and hashed for the summary (deck_sha256, what `sha256sum` prints).
   subroutine read_deck(path, cfg, error)
      character(len=*), intent(in) :: path                !! deck file
      type(run_config), intent(out) :: cfg                !! what it defines
      type(error_type), allocatable, intent(out) :: error !! first problem found
      character(len=:), allocatable :: text

      call read_file_text(path, text, error)
      if (allocated(error)) then
         error%message = "deck: "//error%message
         return
      end if
      call read_deck_string(text, path, cfg, error)
   end subroutine read_deck

   !> Read and validate a deck given as text. The path names the deck in messages, gives
   !> the default output name, and is the base of a relative record_file.
   subroutine read_deck_string(text, path, cfg, error)
      character(len=*), intent(in) :: text                !! the deck, lines separated by newlines
      character(len=*), intent(in) :: path                !! name of the deck
      type(run_config), intent(out) :: cfg                !! what it defines
      type(error_type), allocatable, intent(out) :: error !! first problem found
      type(deck_text) :: deck
      logical :: halting

      ! a value too large for a double ('1e400' in a deck or a record) overflows to infinity
      ! when it is converted, and is then rejected with a message: a build that traps
      ! overflow (-ffpe-trap, tools/test_checked.sh) must not stop there. The halting mode is
      ! saved, switched off while the deck is read, the overflow flag cleared and the mode
      ! set back (gfortran does not restore it on return, as Fortran 2008's 14.3 would).
      ! a deck whose lines end with CR alone would be one line: said so, not "&model is missing"
      if (len_trim(cr_line_ends(text)) > 0) then
         call fatal_error(error, path//trim(cr_line_ends(text)))
         return
      end if
      call ieee_get_halting_mode(ieee_overflow, halting)
      if (ieee_support_halting(ieee_overflow)) call ieee_set_halting_mode(ieee_overflow, .false.)
      call deck_from_string(text, path, deck, error)
      if (.not. allocated(error)) call read_groups(deck, cfg, error)
      call ieee_set_flag(ieee_overflow, .false.)
      if (ieee_support_halting(ieee_overflow)) call ieee_set_halting_mode(ieee_overflow, halting)
      if (allocated(error)) return
      call sha256_text(text, cfg%model%deck_sha256)
   end subroutine read_deck_string

   subroutine read_groups(deck, cfg, error)
      type(deck_text), intent(inout) :: deck   !! (check_groups keeps its groups' places)
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      integer :: stat
      logical :: floors, matrices

      cfg%deck_path = deck%path
      call check_groups(deck, [character(len=12) :: 'model', 'springs', 'damping', 'friction', &
                               'braces', 'isolators', 'storeys', 'floors', 'frames', 'floor_braces', &
                               'matrices', 'excitation', 'excitation2', 'excitation3', 'integration', 'output', &
                               'bearings'], error)
      if (allocated(error)) return
      ! the DOFs: a building of rigid floors (&floors, &frames), a structure's matrices
      ! (&matrices), or masses (&model, &springs)
      call read_floors_group(deck, cfg, floors, error)
      if (allocated(error)) return
      if (.not. floors) call read_matrices_group(deck, cfg, matrices, error)
      if (allocated(error)) return
      call one_model(deck, floors, matrices, error)
      if (allocated(error)) return
      if (floors) then
         call read_frames_group(deck, cfg, error)
      else if (.not. matrices) then
         call read_model_group(deck, cfg, error)
      end if
      if (allocated(error)) return
      call read_springs_group(deck, cfg, error)
      if (allocated(error)) return
      if (.not. floors) then
         if (matrices) call check_definite(deck, cfg, error)
      end if
      if (allocated(error)) return
      if (cfg%model%p_delta) call add_p_delta(deck, cfg, error)
      if (allocated(error)) return
      call read_damping_group(deck, cfg, error)
      if (allocated(error)) return
      call read_friction_group(deck, cfg, error)
      if (allocated(error)) return
      ! the engineers' shorthands, expanded into devices and springs, and the storeys
      call read_braces_group(deck, cfg, error)
      if (allocated(error)) return
      call read_isolators_group(deck, cfg, error)
      if (allocated(error)) return
      if (.not. (floors .or. matrices)) call read_storeys_group(deck, cfg, error)
      if (allocated(error)) return
      ! each device's direction from its two nodes (fd_kinematics)
      call set_pair_directions(cfg%model, stat)
      if (stat /= 0) then
         call no_memory(deck, 'friction', cfg%model%n_devices, 'device directions', error)
         return
      end if
      ! the braces at plan positions of rigid floors: devices of any direction
      if (floors) call read_floor_braces_group(deck, cfg, error)
      if (allocated(error)) return
      ! planar bearings: two devices each, of any direction
      call read_bearings_group(deck, cfg, floors, error)
      if (allocated(error)) return
      call read_excitation_group(deck, cfg, error)
      if (allocated(error)) return
      call read_integration_group(deck, cfg, error)
      if (allocated(error)) return
      call read_output_group(deck, cfg, error)
      if (allocated(error)) return
      ! 'rayleigh' damping from xi at two modes (what the technique can integrate is asked by
      ! the session, fd_technique's check_technique)
      call resolve_rayleigh(deck, cfg, error)
      if (allocated(error)) return
      ! 'modal' damping: the kept modes of the stuck system, once the devices are known
      if (cfg%model%damping == damping_modal) then
         call modal_damping_basis(cfg%model, error)
         if (allocated(error)) error%message = deck%path//", group &damping: "//error%message
      end if
   end subroutine read_groups

   !> The model is one of three kinds: masses (&model), rigid floors (&floors, &frames,
   !> &floor_braces) or matrices (&matrices); the groups of another kind are refused, and
   !> &storeys with floors or matrices (whose storeys are not pairs of nodes).
   subroutine one_model(deck, floors, matrices, error)
      type(deck_text), intent(in) :: deck
      logical, intent(in) :: floors                       !! &floors is given
      logical, intent(in) :: matrices                     !! &matrices is given
      type(error_type), allocatable, intent(out) :: error
      type(group_text) :: grp
      character(len=12), parameter :: names(5) = [character(len=12) :: 'model', 'storeys', 'frames', &
                                                  'floor_braces', 'matrices']
      logical :: found, refused
      integer :: k

      do k = 1, 5
         refused = (k <= 2 .and. (floors .or. matrices)) .or. (k >= 3 .and. k <= 4 .and. .not. floors) .or. &
                   (k == 5 .and. floors)
         if (.not. refused) cycle
         call find_group(deck, trim(names(k)), grp, found, error)
         if (allocated(error)) return
         if (.not. found) cycle
         if (floors) then
            call fatal_error(error, deck%path//": group &"//trim(names(k))//" is not for a building of &floors: "// &
                             "its DOFs and storeys are the floors'")
         else if (matrices .and. k <= 2) then
            call fatal_error(error, deck%path//": group &"//trim(names(k))//" is not for a structure of "// &
                             "&matrices: its DOFs are the matrices'")
         else
            call fatal_error(error, deck%path//": group &"//trim(names(k))//" is for a building of rigid floors: "// &
                             "give &floors (or leave it out)")
         end if
         return
      end do
   end subroutine one_model

   ! ---------------------------------------------------------------- &model
   subroutine read_model_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      integer :: n_dof
      real(dp), allocatable :: mass(:), u0(:), v0(:)
      character(len=label_len), allocatable :: label(:)
      namelist /model/ n_dof, mass, u0, v0, label
      type(group_text) :: grp
      character(len=512) :: msg
      integer :: ios, i, n
      logical :: more

      n_dof = unset_int
      call required_group(deck, 'model', grp, error)
      if (allocated(error)) return
      i = array_capacity(grp, 'n_dof', max_dof)
      allocate (mass(i), u0(i), v0(i), stat=ios)
      if (ios /= 0) then
         call no_memory(deck, 'model', i, 'DOFs', error); return
      end if
      mass = unset; u0 = unset; v0 = unset
      allocate (label(i), stat=ios)
      if (ios /= 0) then
         call no_memory(deck, 'model', i, 'DOFs', error); return
      end if
      label = ''
      ! a longer label would be cut by the namelist read: refused from the group's text first
      call check_length(deck, grp, 'label', label_len - 1, error)
      if (allocated(error)) return
      do
         read (grp%lines, nml=model, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      call need_int(deck, grp, 'n_dof', n_dof, 1, max_dof, error)
      if (allocated(error)) return
      n = n_dof
      call need_reals(deck, grp, 'mass', mass, n, 'kg', error, positive=.true.)
      if (allocated(error)) return
      call optional_reals(deck, grp, 'u0', u0, n, default_u0, 'm', error)
      if (allocated(error)) return
      call optional_reals(deck, grp, 'v0', v0, n, default_v0, 'm/s', error)
      if (allocated(error)) return
      call check_labels(deck, grp, 'model', label, n, error)
      if (allocated(error)) return
      cfg%model%dof_label = label(1:n)
      cfg%model%n_dof = n
      cfg%model%mass = mass(1:n)
      cfg%model%u0 = u0(1:n)
      cfg%model%v0 = v0(1:n)
   end subroutine read_model_group

   ! ---------------------------------------------------------------- &springs
   subroutine read_springs_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      integer :: n_springs
      integer, allocatable :: node_i(:), node_j(:)
      real(dp), allocatable :: k(:)
      namelist /springs/ n_springs, node_i, node_j, k
      type(group_text) :: grp
      character(len=512) :: msg
      integer :: ios, i, n
      logical :: more, found

      n_springs = unset_int
      if (cfg%model%n_floors > 0 .or. cfg%model%n_kx > 0) then
         ! rigid floors or matrices: springs between their DOFs are optional
         call find_group(deck, 'springs', grp, found, error)
         if (allocated(error)) return
         if (.not. found) then
            cfg%model%n_springs = 0
            allocate (cfg%model%spring_i(0), cfg%model%spring_j(0), cfg%model%spring_k(0), &
                      cfg%model%spring_source(0))
            return
         end if
      else
         call required_group(deck, 'springs', grp, error)
      end if
      if (allocated(error)) return
      i = array_capacity(grp, 'n_springs', max_springs)
      allocate (node_i(i), node_j(i), k(i), stat=ios)
      if (ios /= 0) then
         call no_memory(deck, 'springs', i, 'springs', error); return
      end if
      node_i = unset_int; node_j = unset_int; k = unset
      do
         read (grp%lines, nml=springs, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      call need_int(deck, grp, 'n_springs', n_springs, 0, max_springs, error)
      if (allocated(error)) return
      n = n_springs
      call node_list(deck, grp, 'node_i', node_i, n, 1, cfg%model%n_dof, error)
      if (allocated(error)) return
      call node_list(deck, grp, 'node_j', node_j, n, 0, cfg%model%n_dof, error)
      if (allocated(error)) return
      call need_reals(deck, grp, 'k', k, n, 'N/m', error, positive=.true.)
      if (allocated(error)) return
      do i = 1, n
         call distinct_nodes(deck, 'springs', i, node_i(i), node_j(i), 'a spring joins two different nodes', error)
         if (allocated(error)) return
      end do
      cfg%model%n_springs = n
      cfg%model%spring_i = node_i(1:n)
      cfg%model%spring_j = node_j(1:n)
      cfg%model%spring_k = k(1:n)
      allocate (cfg%model%spring_source(n))
      cfg%model%spring_source = source_friction
   end subroutine read_springs_group

   ! ---------------------------------------------------------------- &damping
   subroutine read_damping_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      character(len=name_len) :: damping_type
      real(dp) :: period, rayleigh_a0, rayleigh_a1
      real(dp), allocatable :: xi(:)
      integer :: mode_i, mode_j, modal_modes
      character(len=name_len) :: mode_system
      namelist /damping/ damping_type, xi, period, rayleigh_a0, rayleigh_a1, mode_i, mode_j, mode_system, modal_modes
      type(group_text) :: grp
      character(len=512) :: msg
      character(len=:), allocatable :: choices
      logical, allocatable :: given(:)
      integer :: ios, nx
      logical :: more

      damping_type = ''
      ! xi: one ratio, or ('modal') one per mode: at most one a DOF (and a few more, which
      ! the checks below report)
      allocate (xi(2*cfg%model%n_dof + 16))
      xi = default_xi; period = default_period
      rayleigh_a0 = default_rayleigh_a0; rayleigh_a1 = default_rayleigh_a1
      mode_i = unset_int; mode_j = unset_int; mode_system = mode_systems(default_mode_system)%name
      modal_modes = default_modal_modes
      call required_group(deck, 'damping', grp, error)
      if (allocated(error)) return
      call check_lengths(deck, grp, [character(len=16) :: 'damping_type', 'mode_system'], [name_len, name_len], error)
      if (allocated(error)) return
      do
         read (grp%lines, nml=damping, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      given = given_of(grp, 'xi', size(xi))
      nx = count(given)
      if (nx > 0 .and. .not. all(given(1:nx))) then
         call fatal_error(error, deck%path//", group &damping: xi is given as elements that do not start at "// &
                          "xi(1) or have gaps: give xi = x1, x2, ... in order")
         return
      end if
      cfg%model%damping = keyword_id(damping_types, damping_type)
      if (cfg%model%damping /= damping_modal) then
         if (nx > 1) then
            call bad(deck, 'damping', 'xi', trim(fmt_int(nx))//' values', "one value unless damping_type = "// &
                     "'modal' (a ratio per mode)", error)
            return
         end if
         if (is_given(grp, 'modal_modes')) then
            call bad(deck, 'damping', 'modal_modes', trim(fmt_int(modal_modes)), "absent unless damping_type = "// &
                     "'modal'", error)
            return
         end if
      end if
      select case (cfg%model%damping)
      case (damping_stiffness)
         call check_real(deck, 'damping', 'xi', xi(1), 0.0_dp, 1.0_dp, '', error, open_hi=.true.)
         if (allocated(error)) return
         call check_real(deck, 'damping', 'period', period, 0.0_dp, max_magnitude, 's', error)
         if (allocated(error)) return
      case (damping_rayleigh)
         call check_real(deck, 'damping', 'rayleigh_a0', rayleigh_a0, 0.0_dp, max_magnitude, '1/s', error)
         if (allocated(error)) return
         call check_real(deck, 'damping', 'rayleigh_a1', rayleigh_a1, 0.0_dp, max_magnitude, 's', error)
         if (allocated(error)) return
         call rayleigh_modes(deck, xi(1), rayleigh_a0, rayleigh_a1, mode_i, mode_j, is_given(grp, 'mode_i'), &
                             is_given(grp, 'mode_j'), mode_system, cfg, error)
         if (allocated(error)) return
      case (damping_modal)
         call modal_ratios(deck, grp, xi(1:nx), modal_modes, cfg, error)
         if (allocated(error)) return
      case (damping_none)
      case default
         call keyword_choices(damping_types, choices)
         call bad(deck, 'damping', 'damping_type', "'"//trim(damping_type)//"'", 'one of '//choices, error)
         return
      end select
      cfg%model%xi = xi(1)
      cfg%model%period = period
      cfg%model%rayleigh_a0 = rayleigh_a0
      cfg%model%rayleigh_a1 = rayleigh_a1
   end subroutine read_damping_group

   !> 'modal' damping: xi (one ratio for every kept mode, or one per kept mode, each in
   !> [0, 1)) and modal_modes (>= 1 when given); the variables of the other damping types
   !> are refused rather than left unused. The modes are found once the devices are known
   !> (fd_modal_damping, from read_groups).
   subroutine modal_ratios(deck, grp, xi, modal_modes, cfg, error)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp
      real(dp), intent(in) :: xi(:)                 !! the ratios given
      integer, intent(in) :: modal_modes
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      character(len=12), parameter :: others(*) = [character(len=12) :: 'period', 'rayleigh_a0', 'rayleigh_a1', &
                                                   'mode_i', 'mode_j', 'mode_system']
      integer :: i

      if (size(xi) == 0) then
         call fatal_error(error, deck%path//", group &damping: xi is not given: 'modal' damping needs the damping "// &
                          "ratio of the modes (one for every kept mode, or one per mode)")
         return
      end if
      do i = 1, size(others)
         if (is_given(grp, trim(others(i)))) then
            call fatal_error(error, deck%path//", group &damping: "//trim(others(i))//" is given: it must be "// &
                             "absent with 'modal' damping (xi and modal_modes set it)")
            return
         end if
      end do
      do i = 1, size(xi)
         if (size(xi) == 1) then
            call check_real(deck, 'damping', 'xi', xi(i), 0.0_dp, 1.0_dp, '', error, open_hi=.true.)
         else
            call check_real(deck, 'damping', 'xi('//trim(fmt_int(i))//')', xi(i), 0.0_dp, 1.0_dp, '', error, &
                            open_hi=.true.)
         end if
         if (allocated(error)) return
      end do
      if (is_given(grp, 'modal_modes')) then
         if (modal_modes < 1 .or. modal_modes > cfg%model%n_dof) then
            call bad(deck, 'damping', 'modal_modes', trim(fmt_int(modal_modes)), 'in 1..'// &
                     trim(fmt_int(cfg%model%n_dof))//' (n_dof)', error)
            return
         end if
      end if
      cfg%model%modal_xi = xi
      cfg%model%modal_modes = modal_modes
   end subroutine modal_ratios

   ! ---------------------------------------------------------------- &friction
   subroutine read_friction_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      integer :: n_devices
      integer, allocatable :: node_i(:), node_j(:)
      character(len=name_len), allocatable :: law(:)
      real(dp), allocatable :: p(:), mu(:), eps(:), eps1(:), f(:)
      character(len=name_len), allocatable :: mu_law(:)
      real(dp), allocatable :: mu_max(:), mu_min(:), mu_rate(:), mu_table_v(:, :), mu_table_mu(:, :)
      character(len=label_len), allocatable :: label(:)
      integer, allocatable :: mu_ids(:)
      logical, allocatable :: g_mu(:), g_table(:, :)
      namelist /friction/ n_devices, node_i, node_j, law, p, mu, eps, eps1, f, &
         mu_law, mu_max, mu_min, mu_rate, mu_table_v, mu_table_mu, label
      type(group_text) :: grp
      character(len=512) :: msg
      character(len=:), allocatable :: idx
      integer :: ios, i, n, id
      logical :: found, more

      n_devices = default_n_devices
      call find_group(deck, 'friction', grp, found, error)
      if (allocated(error)) return
      cfg%model%n_devices = 0
      allocate (cfg%model%dev(0))
      if (.not. found) return
      i = array_capacity(grp, 'n_devices', max_devices)
      allocate (node_i(i), node_j(i), law(i), p(i), mu(i), eps(i), eps1(i), f(i), stat=ios)
      if (ios /= 0) then
         call no_memory(deck, 'friction', i, 'devices', error); return
      end if
      node_i = unset_int; node_j = unset_int; law = ''
      p = unset; mu = unset; eps = unset; eps1 = unset; f = unset
      call new_mu_inputs(i, mu_law, mu_max, mu_min, mu_rate, mu_table_v, mu_table_mu, label, ios)
      if (ios /= 0) then
         call no_memory(deck, 'friction', i, 'devices', error); return
      end if
      ! a longer label would be cut by the namelist read: refused from the group's text first
      call check_lengths(deck, grp, [character(len=16) :: 'law', 'mu_law', 'label'], [name_len, name_len, label_len - 1], &
                         error)
      if (allocated(error)) return
      do
         read (grp%lines, nml=friction, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      call need_int(deck, 'friction', 'n_devices', n_devices, .true., 0, max_devices, error)
      if (allocated(error)) return
      n = n_devices
      call node_list(deck, grp, 'node_i', node_i, n, 1, cfg%model%n_dof, error)
      if (allocated(error)) return
      call node_list(deck, grp, 'node_j', node_j, n, 0, cfg%model%n_dof, error)
      if (allocated(error)) return
      call need_reals(deck, grp, 'p', p, n, 'N', error, positive=.false.)
      if (allocated(error)) return
      g_mu = given_of(grp, 'mu', size(mu))
      call read_mu_laws(deck, grp, n, mu_law, mu, g_mu, mu_max, mu_min, mu_rate, mu_table_v, mu_table_mu, &
                        mu_ids, g_table, error)
      if (allocated(error)) return
      call check_labels(deck, grp, 'friction', label, n, error)
      if (allocated(error)) return
      call need_reals(deck, 'friction', 'mu', mu, g_mu, n, '', error, positive=.false.)
      if (allocated(error)) return
      call optional_reals(deck, grp, 'eps', eps, n, default_eps, 'm/s', error, positive=.true.)
      if (allocated(error)) return
      call optional_reals(deck, grp, 'eps1', eps1, n, default_eps1, 'm/s', error, positive=.true.)
      if (allocated(error)) return
      call optional_reals(deck, grp, 'f', f, n, default_f, 'm', error, positive=.true.)
      if (allocated(error)) return
      if (any(law(n + 1:) /= '')) then
         call bad(deck, 'friction', 'law', 'with '//trim(fmt_int(findloc(law /= '', .true., 1, back=.true.))) &
                  //' values', 'at most n_devices = '//trim(fmt_int(n))//' values', error)
         return
      end if
      deallocate (cfg%model%dev)
      allocate (cfg%model%dev(n), stat=ios)
      if (ios /= 0) then
         call fatal_error(error, deck%path//", group &friction: not enough memory for "//trim(fmt_int(n))//" devices", &
                          stat_no_memory)
         return
      end if
      do i = 1, n
         idx = '('//trim(fmt_int(i))//')'
         call distinct_nodes(deck, 'friction', i, node_i(i), node_j(i), 'a device joins two different nodes', error)
         if (allocated(error)) return
         if (p(i)*mu(i) /= 0.0_dp .and. p(i)*mu(i) < min_scale) then
            call bad(deck, 'friction', 'p'//idx//' * mu'//idx, trim(fmt_real(p(i)*mu(i))), '0 (no friction) or at '// &
                     'least '//trim(fmt_real(min_scale))//' N: the friction force P mu of a device (here P = '// &
                     trim(fmt_real(p(i)))//' N, mu = '//trim(fmt_real(mu(i)))//')', error)
            return
         end if
         call device_law(deck, 'friction', i, law(i), id, error)
         if (allocated(error)) return
         cfg%model%dev(i) = device_type(node_i=node_i(i), node_j=node_j(i), law=id, &
                                        p=p(i), mu=mu(i), eps=eps(i), eps1=eps1(i), f=f(i))
         call apply_mu_law(deck, 'friction', i, mu_ids(i), mu_min(i), mu_rate(i), mu_table_v(:, i), &
                           mu_table_mu(:, i), g_table(:, i), cfg%model%dev(i), error)
         if (allocated(error)) return
         cfg%model%dev(i)%label = label(i)
         cfg%model%dev(i)%source_index = i
      end do
      cfg%model%n_devices = n
   end subroutine read_friction_group

   ! ---------------------------------------------------------------- &excitation
   subroutine read_excitation_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a
      integer :: f
      logical :: found

      call read_component(deck, 'excitation', .true., cfg%exc, cfg%record, found, error)
      if (allocated(error)) return
      call read_vertical_component(deck, cfg, error)
      if (allocated(error)) return
      ! a second horizontal component: perpendicular to the first, for rigid floors
      call read_component(deck, 'excitation2', .false., cfg%exc2, cfg%record2, found, error)
      if (allocated(error) .or. .not. found) return
      if (cfg%model%n_floors == 0 .and. .not. allocated(cfg%model%influence2)) then
         call fatal_error(error, deck%path//": group &excitation2 is the second horizontal component of a "// &
                          "building of rigid floors (&floors), or of &matrices with influence2: a model of &model "// &
                          "has one direction")
         return
      end if
      call same_record_step(deck, 'excitation2', cfg%exc2%dt_record, cfg%exc%dt_record, 'the two components', error)
      if (allocated(error)) return
      if (cfg%model%n_floors == 0) return   ! &matrices gives influence2
      ! r2 = (-sin a, cos a, 0): along excitation_angle + 90 degrees
      allocate (cfg%model%influence2(cfg%model%n_dof))
      do f = 1, cfg%model%n_floors
         a = cfg%model%influence(floor_dof(f, 1))
         cfg%model%influence2(floor_dof(f, [1, 2, 3])) = [-cfg%model%influence(floor_dof(f, 2)), a, 0.0_dp]
      end do
   end subroutine read_excitation_group

   !> The vertical component (&excitation3): the ground's vertical acceleration a_z (upward
   !> positive), which scales each bearing's normal force, N = N0 (1 + a_z / g); the vertical
   !> support is rigid (no vertical DOF). Only bearings (&bearings) take it.
   subroutine read_vertical_component(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      logical :: found

      call read_component(deck, 'excitation3', .false., cfg%exc3, cfg%record3, found, error)
      if (allocated(error) .or. .not. found) return
      if (.not. any(cfg%model%dev(1:cfg%model%n_devices)%partner > 0)) then
         call fatal_error(error, deck%path//": group &excitation3 is the vertical ground motion, which changes "// &
                          "the normal force of planar bearings (&bearings): the deck has none, and nothing else "// &
                          "takes it; remove &excitation3 or add &bearings")
         return
      end if
      call same_record_step(deck, 'excitation3', cfg%exc3%dt_record, cfg%exc%dt_record, 'the components', error)
   end subroutine read_vertical_component

   !> A further component's dt_record must be &excitation's: the components share the step.
   subroutine same_record_step(deck, gname, dt, dt_first, components, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: gname               !! the further component's group
      real(dp), intent(in) :: dt                          !! its dt_record [s]
      real(dp), intent(in) :: dt_first                    !! &excitation's [s]
      character(len=*), intent(in) :: components          !! the components, as the message names them
      type(error_type), allocatable, intent(out) :: error
      if (dt == dt_first) return
      call bad(deck, gname, 'dt_record', trim(fmt_real(dt)), "equal to &excitation's "//trim(fmt_real(dt_first))// &
               ' s ('//components//' share the step dt1 = dt_record / n1)', error)
   end subroutine same_record_step

   subroutine read_component(deck, gname, required, exc, record, found, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: gname               !! the group: 'excitation' or 'excitation2'
      logical, intent(in) :: required                     !! the deck must give it
      type(excitation_type), intent(inout) :: exc         !! the component read
      type(record_info), intent(inout) :: record          !! its record, if one
      logical, intent(out) :: found                       !! the deck gives the group
      type(error_type), allocatable, intent(out) :: error
      character(len=name_len) :: excitation_type, record_kind, record_format, record_units
      integer :: kind_id
      character(len=path_len) :: record_file
      real(dp) :: amplitude, frequency, duration, dt_record, record_scale, factor
      integer :: ramp_cycles
      logical :: known, given_dt, given_duration
      namelist /excitation/ excitation_type, amplitude, frequency, ramp_cycles, duration, dt_record, &
         record_file, record_kind, record_scale, record_format, record_units
      type(group_text) :: grp
      character(len=512) :: msg
      character(len=:), allocatable :: path, choices
      integer :: ios
      logical :: more

      excitation_type = ''; record_kind = record_kinds(default_record_kind)%name; record_file = ''
      amplitude = unset; frequency = unset; duration = unset; dt_record = unset
      record_scale = default_record_scale
      ramp_cycles = default_ramp_cycles
      record_format = 'auto'; record_units = ''
      if (required) then
         call required_group(deck, gname, grp, error)
         found = .true.
      else
         call find_group(deck, gname, grp, found, error)
         if (.not. found) return
      end if
      if (allocated(error)) return
      ! the namelist read takes the group by the name of its namelist statement
      if (gname /= 'excitation') then
         ios = index(lower(grp%lines(1)), '&'//gname)
         grp%lines(1)(ios:ios + len(gname)) = '&excitation'//repeat(' ', len(gname) - len('excitation'))
      end if
      call check_lengths(deck, grp, [character(len=16) :: 'excitation_type', 'record_kind', 'record_format', &
                                     'record_units', 'record_file'], [name_len, name_len, name_len, name_len, path_len], &
                         error)
      if (allocated(error)) return
      do
         read (grp%lines, nml=excitation, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      ! a record whose file gives DT (AT2) may leave dt_record out
      given_dt = is_given(grp, 'dt_record')
      given_duration = is_given(grp, 'duration')
      if (.not. (keyword_id(excitation_types, excitation_type) == excitation_record .and. .not. given_dt)) then
         call need_real(deck, gname, 'dt_record', dt_record, given_dt, 's', error)
         if (allocated(error)) return
      end if
      exc%dt_record = dt_record
      exc%kind = keyword_id(excitation_types, excitation_type)
      select case (exc%kind)
      case (excitation_harmonic)
         call need_real(deck, gname, 'amplitude', amplitude, is_given(grp, 'amplitude'), 'm', error, &
                        positive=.false.)
         if (allocated(error)) return
         call need_real(deck, gname, 'frequency', frequency, is_given(grp, 'frequency'), 'Hz', error)
         if (allocated(error)) return
         if (ramp_cycles < 0) then
            call bad(deck, gname, 'ramp_cycles', trim(fmt_int(ramp_cycles)), '>= 0', error); return
         end if
         call need_real(deck, gname, 'duration', duration, given_duration, 's', error)
         if (allocated(error)) return
         exc%amplitude = amplitude
         exc%frequency = frequency
         exc%ramp_cycles = ramp_cycles
      case (excitation_record)
         if (len_trim(record_file) == 0) then
            call bad(deck, gname, 'record_file', "''", 'the path of the record file', error); return
         end if
         if (.not. ieee_is_finite(record_scale) .or. record_scale == 0.0_dp) then
            call bad(deck, gname, 'record_scale', trim(fmt_real(record_scale)), 'finite and non-zero', error)
            return
         end if
         call check_magnitude(deck, gname, 'record_scale', record_scale, '', .true., error)
         if (allocated(error)) return
         call keyword_value(deck, gname, 'record_kind', record_kinds, record_kind, kind_id, error)
         if (allocated(error)) return
         select case (lower(trim(record_format)))
         case ('auto', 'at2', 'values', 'time_value')
         case default
            call bad(deck, gname, 'record_format', "'"//trim(record_format)//"'", 'one of '//record_formats, error)
            return
         end select
         if (len_trim(record_units) > 0) then
            call units_factor(lower(trim(record_units)), kind_id == record_displacement, factor, known)
            if (.not. known) then
               call bad(deck, gname, 'record_units', "'"//trim(record_units)//"'", 'one of '// &
                        record_units_list//", matching record_kind = '"//trim(record_kind)//"'", error)
               return
            end if
         end if
         call relative_to(deck%path, trim(record_file), path)
         call read_record(path, trim(record_format), kind_id == record_displacement, &
                          trim(record_units), record_scale, merge(dt_record, 0.0_dp, given_dt), &
                          exc%acc, record, error)
         if (allocated(error)) then
            error%message = deck%path//", group &"//gname//", record_file = '"//trim(fmt_text(record_file))//"': "// &
                            error%message
            return
         end if
         record%path = trim(record_file)   ! as the deck gives it (like the summary's "deck")
         dt_record = record%dt
         exc%dt_record = dt_record
         call check_magnitude(deck, gname, "dt_record (the record file's DT)", dt_record, 's', .true., error)
         if (allocated(error)) return
         if (.not. (record%peak_acc <= max_magnitude)) then
            call bad(deck, gname, 'record_file', "'"//trim(fmt_text(record_file))//"'", 'a record whose table '// &
                     'acceleration (after record_units and record_scale = '//trim(fmt_real(record_scale))// &
                     ') stays within '//trim(fmt_real(max_magnitude))//' m/s2 in magnitude; it reaches '// &
                     trim(fmt_real(record%peak_acc))//' m/s2', error)
            return
         end if
         if (.not. given_duration) duration = (size(exc%acc) - 1)*dt_record
         given_duration = .true.
         call need_real(deck, gname, 'duration', duration, given_duration, 's', error)
         if (allocated(error)) return
      case (excitation_none)
         call need_real(deck, gname, 'duration', duration, given_duration, 's', error)
         if (allocated(error)) return
      case default
         call keyword_choices(excitation_types, choices)
         call bad(deck, gname, 'excitation_type', "'"//trim(excitation_type)//"'", 'one of '//choices, error)
         return
      end select
      exc%duration = duration
   end subroutine read_component

   ! ---------------------------------------------------------------- &integration
   subroutine read_integration_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      character(len=name_len) :: technique, linear_system, refinement
      real(dp) :: beta, gamma, n, dt_min, theta, tolerance, tolerance_floor
      integer :: n1, n2
      logical :: check_correctness
      namelist /integration/ technique, beta, gamma, n1, n2, n, check_correctness, dt_min, theta, linear_system, &
                             refinement, tolerance, tolerance_floor
      type(group_text) :: grp
      character(len=512) :: msg
      integer :: ios, technique_id, system_id, refinement_id
      logical :: found, more, given_tol, given_floor

      technique = technique_name(default_technique)
      linear_system = linear_systems(default_linear_system)%name
      refinement = refinements(default_refinement)%name
      beta = default_beta; gamma = default_gamma; n1 = default_n1; n2 = default_n2; n = default_n
      check_correctness = default_check_correctness; dt_min = default_dt_min; theta = default_theta
      tolerance = 0.0_dp; tolerance_floor = 0.0_dp
      given_tol = .false.; given_floor = .false.
      call find_group(deck, 'integration', grp, found, error)
      if (allocated(error)) return
      if (found) then
         call check_lengths(deck, grp, [character(len=16) :: 'technique', 'linear_system', 'refinement'], &
                            [name_len, name_len, name_len], error)
         if (allocated(error)) return
         do
            read (grp%lines, nml=integration, iostat=ios, iomsg=msg)
            call next_read(deck, grp, ios, msg, more, error)
            if (.not. more) exit
         end do
         if (allocated(error)) return
         given_tol = is_given(grp, 'tolerance')
         given_floor = is_given(grp, 'tolerance_floor')
      end if
      call keyword_value(deck, 'integration', 'technique', techniques, technique, technique_id, error)
      if (allocated(error)) return
      call keyword_value(deck, 'integration', 'linear_system', linear_systems, linear_system, system_id, error)
      if (allocated(error)) return
      call keyword_value(deck, 'integration', 'refinement', refinements, refinement, refinement_id, error)
      if (allocated(error)) return
      call check_real(deck, 'integration', 'beta', beta, 0.0_dp, 0.5_dp, '', error, open_lo=.true.)
      if (allocated(error)) return
      call check_real(deck, 'integration', 'gamma', gamma, 0.5_dp, 1.0_dp, '', error)
      if (allocated(error)) return
      if (n1 < 1) then
         call bad(deck, 'integration', 'n1', trim(fmt_int(n1)), '>= 1 (dt1 = dt_record / n1)', error); return
      end if
      if (n2 < 1) then
         call bad(deck, 'integration', 'n2', trim(fmt_int(n2)), '>= 1 (dt2 = dt1 / n2)', error); return
      end if
      if (.not. ieee_is_finite(n) .or. n <= 1.0_dp) then
         call bad(deck, 'integration', 'n', trim(fmt_real(n)), '> 1 (correctness condition, eqs. 9 and 12)', error)
         return
      end if
      call check_magnitude(deck, 'integration', 'n', n, '', .false., error)
      if (allocated(error)) return
      call check_real(deck, 'integration', 'dt_min', dt_min, 0.0_dp, cfg%exc%dt_record/n1/n2, 's', error)
      if (allocated(error)) return
      call check_real(deck, 'integration', 'theta', theta, 0.5_dp, 1.0_dp, '', error)
      if (allocated(error)) return
      call refuse_tolerance(deck, tolerance, given_tol, tolerance_floor, given_floor, error)
      if (allocated(error)) return
      ! the run takes duration / dt1 steps, counted in a default integer
      if (cfg%exc%duration/(cfg%exc%dt_record/n1) > 2.0e9_dp) then
         call bad(deck, 'integration', 'n1', trim(fmt_int(n1)), 'such that duration / (dt_record / n1) = '// &
                  trim(fmt_real(cfg%exc%duration/(cfg%exc%dt_record/n1)))//' steps stays below 2e9 (duration = '// &
                  trim(fmt_real(cfg%exc%duration))//' s and dt_record = '//trim(fmt_real(cfg%exc%dt_record))// &
                  ' s of &excitation)', error)
         return
      end if
      cfg%opts%technique = technique_id
      cfg%opts%beta = beta
      cfg%opts%gamma = gamma
      cfg%opts%n1 = n1
      cfg%opts%n2 = n2
      cfg%opts%n_corr = n
      cfg%opts%check = check_correctness
      cfg%opts%dt_min = dt_min
      cfg%opts%theta = theta
      cfg%opts%linear_system = system_id
      cfg%opts%refinement = refinement_id
   end subroutine read_integration_group

   !> A tolerance run (tolerance, tolerance_floor of &integration) chooses the technique and
   !> refines it from Python (frictiondyn.tolerance): this reader runs one setting, so a deck
   !> that gives either is refused, its values validated first.
   subroutine refuse_tolerance(deck, tolerance, given_tol, tolerance_floor, given_floor, error)
      type(deck_text), intent(in) :: deck
      real(dp), intent(in) :: tolerance, tolerance_floor
      logical, intent(in) :: given_tol, given_floor            !! each given in the deck's text
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: how = ' is a tolerance run, made by Python: python -m frictiondyn run '// &
         'DECK (or frictiondyn.run); this executable and the session run one setting of the deck'
      if (given_tol) then
         call check_real(deck, 'integration', 'tolerance', tolerance, 0.0_dp, 1.0_dp, '', error, &
                         open_lo=.true., open_hi=.true.)
         if (allocated(error)) return
         call fatal_error(error, deck%path//', group &integration: tolerance = '//trim(fmt_real(tolerance))//how)
      else if (given_floor) then
         call check_real(deck, 'integration', 'tolerance_floor', tolerance_floor, 0.0_dp, 1.0_dp, '', error)
         if (allocated(error)) return
         call fatal_error(error, deck%path//', group &integration: tolerance_floor = '// &
                          trim(fmt_real(tolerance_floor))//how)
      end if
   end subroutine refuse_tolerance

   ! ---------------------------------------------------------------- &output
   subroutine read_output_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      character(len=path_len) :: dir, name
      integer :: output_every, n_modes, max_history_mb
      logical :: write_history
      integer, allocatable :: history_dofs(:), history_devices(:)
      namelist /output/ dir, name, output_every, write_history, history_dofs, history_devices, n_modes, &
         max_history_mb
      type(group_text) :: grp
      character(len=512) :: msg
      integer :: ios
      logical :: found, more

      dir = default_dir; output_every = default_output_every; write_history = default_write_history
      allocate (history_dofs(cfg%model%n_dof + 2), history_devices(cfg%model%n_devices + 2), stat=ios)
      if (ios /= 0) then
         call no_memory(deck, 'output', cfg%model%n_dof + cfg%model%n_devices, 'history_dofs and history_devices', &
                        error); return
      end if
      history_dofs = unset_int; history_devices = unset_int
      n_modes = default_n_modes
      max_history_mb = default_max_history_mb
      call stem(deck%path, name)
      call find_group(deck, 'output', grp, found, error)
      if (allocated(error)) return
      if (found) then
         call check_lengths(deck, grp, [character(len=16) :: 'dir', 'name'], [path_len, path_len], error)
         if (allocated(error)) return
         do
            read (grp%lines, nml=output, iostat=ios, iomsg=msg)
            call next_read(deck, grp, ios, msg, more, error)
            if (.not. more) exit
         end do
         if (allocated(error)) return
      end if
      if (len_trim(dir) == 0) then
         call bad(deck, 'output', 'dir', "''", 'a directory path', error); return
      end if
      if (len_trim(name) == 0 .or. index(trim(name), '/') > 0) then
         call bad(deck, 'output', 'name', "'"//trim(fmt_text(name))//"'", 'a file name without directory', error); return
      end if
      if (output_every < 0) then
         call bad(deck, 'output', 'output_every', trim(fmt_int(output_every)), '>= 0 (0 = at the record step)', error)
         return
      end if
      call history_list(deck, 'history_dofs', history_dofs, given_of(grp, 'history_dofs', size(history_dofs)), &
                        cfg%model%n_dof, cfg%out%history_dofs, error)
      if (allocated(error)) return
      call history_list(deck, 'history_devices', history_devices, given_of(grp, 'history_devices', &
                        size(history_devices)), cfg%model%n_devices, cfg%out%history_devices, error)
      if (allocated(error)) return
      cfg%out%dir = trim(dir)
      cfg%out%name = trim(name)
      cfg%out%history = write_history
      cfg%opts%output_every = output_every
      if (n_modes < 0) then
         call bad(deck, 'output', 'n_modes', trim(fmt_int(n_modes)), '>= 0 (0 = no modes)', error)
         return
      end if
      cfg%opts%n_modes = n_modes
      if (max_history_mb < 1) then
         call bad(deck, 'output', 'max_history_mb', trim(fmt_int(max_history_mb)), '>= 1 (MiB)', error)
         return
      end if
      if (write_history) call check_history_size(deck, cfg, max_history_mb, error)
   end subroutine read_output_group

   !> The history file a run writes must stay within max_history_mb MiB: its size is known
   !> before the run (samples and columns, 25 bytes a value); a larger one is refused with
   !> the settings that shrink it.
   subroutine check_history_size(deck, cfg, max_history_mb, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(in) :: cfg
      integer, intent(in) :: max_history_mb               !! the limit, MiB
      type(error_type), allocatable, intent(out) :: error
      integer :: ncol, nout, nsteps, every, nk, ndk
      real(dp) :: bytes
      character(len=:), allocatable :: keep

      nk = cfg%model%n_dof
      ndk = cfg%model%n_devices
      if (allocated(cfg%out%history_dofs)) nk = size(cfg%out%history_dofs)
      if (allocated(cfg%out%history_devices)) ndk = size(cfg%out%history_devices)
      call history_shape(cfg%model, cfg%exc, cfg%opts, ncol, nout, nsteps, every, nk, ndk)
      bytes = 25.0_dp*real(ncol, dp)*real(nout, dp)
      if (bytes <= real(max_history_mb, dp)*1048576.0_dp) return
      keep = ''
      if (nk + ndk > 0) keep = ', keep fewer DOFs and devices (history_dofs, history_devices: '// &
                               trim(fmt_int(nk))//' and '//trim(fmt_int(ndk))//' now)'
      call fatal_error(error, deck%path//", group &output: the history would take "//trim(size_text(bytes))//" ("// &
                       trim(fmt_int(nout))//" samples of "//trim(fmt_int(ncol))//" columns), more than "// &
                       "max_history_mb = "//trim(fmt_int(max_history_mb))//" MiB: raise output_every (a sample "// &
                       "every "//trim(fmt_int(every))//" dt1 steps now, of "//trim(fmt_int(nsteps))//")"//keep// &
                       ", set write_history = .false., or raise max_history_mb")
   contains
      pure function size_text(b) result(str)
         real(dp), intent(in) :: b
         character(len=32) :: str
         if (b >= 1024.0_dp**3) then
            write (str, '(f0.1,a)') b/1024.0_dp**3, ' GiB'
         else
            write (str, '(f0.1,a)') b/1024.0_dp**2, ' MiB'
         end if
      end function size_text
   end subroutine check_history_size

   !> A list of DOFs or devices for the history: not given, all (list not allocated); a single
   !> 0, none; else numbers in 1..n, increasing, without repeats.
   subroutine history_list(deck, var, x, given, n, list, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: var
      integer, intent(in) :: x(:), n
      logical, intent(in) :: given(:)                     !! the elements the deck gives
      integer, allocatable, intent(inout) :: list(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: m, i

      m = count(given)
      if (m == 0) return
      if (any(given(m + 1:))) then
         call bad(deck, 'output', var, 'with a gap', 'a list of consecutive values', error); return
      end if
      if (m == 1 .and. x(1) == 0) then
         allocate (list(0))
         return
      end if
      do i = 1, m
         if (x(i) < 1 .or. x(i) > n) then
            call bad(deck, 'output', var//'('//trim(fmt_int(i))//')', trim(fmt_int(x(i))), &
                     'in 1..'//trim(fmt_int(n))//' (or a single 0: none)', error); return
         end if
         if (i > 1) then
            if (x(i) <= x(i - 1)) then
               call bad(deck, 'output', var//'('//trim(fmt_int(i))//')', trim(fmt_int(x(i))), &
                        'greater than '//var//'('//trim(fmt_int(i - 1))//') = '//trim(fmt_int(x(i - 1)))// &
                        ' (increasing, without repeats)', error); return
            end if
         end if
      end do
      list = x(1:m)
   end subroutine history_list
   ! ---------------------------------------------------------------- &floors
   !> A building of rigid floors (fd_floors): floor f has the DOFs ux, uy, rz at its centre
   !> of mass, its mass and rotational inertia (given, or from its plan dimensions). The
   !> table motion acts along excitation_angle in plan (the influence vector r).
   subroutine read_floors_group(deck, cfg, found, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error
      integer :: n_floors
      real(dp), allocatable :: mass(:), inertia(:), plan_x(:), plan_y(:), cm_x(:), cm_y(:), height(:)
      real(dp) :: excitation_angle, c, s
      logical :: p_delta
      character(len=label_len), allocatable :: label(:)
      namelist /floors/ n_floors, mass, inertia, plan_x, plan_y, cm_x, cm_y, height, label, excitation_angle, &
         p_delta
      type(group_text) :: grp
      character(len=512) :: msg
      character(len=:), allocatable :: idx
      logical, allocatable :: g_in(:), g_px(:), g_py(:)
      integer :: ios, i, n, f
      logical :: more

      n_floors = unset_int
      excitation_angle = 0.0_dp
      p_delta = .false.
      call find_group(deck, 'floors', grp, found, error)
      if (allocated(error) .or. .not. found) return
      i = array_capacity(grp, 'n_floors', max_floors)
      allocate (mass(i), inertia(i), plan_x(i), plan_y(i), cm_x(i), cm_y(i), height(i), label(i), stat=ios)
      if (ios /= 0) then
         call no_memory(deck, 'floors', i, 'floors', error); return
      end if
      mass = unset; inertia = unset; plan_x = unset; plan_y = unset; cm_x = unset; cm_y = unset; height = unset
      label = ''
      call check_length(deck, grp, 'label', label_len - 1, error)
      if (allocated(error)) return
      do
         read (grp%lines, nml=floors, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      call need_int(deck, grp, 'n_floors', n_floors, 1, max_floors, error)
      if (allocated(error)) return
      n = n_floors
      call need_reals(deck, grp, 'mass', mass, n, 'kg', error, positive=.true.)
      if (allocated(error)) return
      call optional_reals(deck, grp, 'cm_x', cm_x, n, 0.0_dp, 'm', error)
      if (allocated(error)) return
      call optional_reals(deck, grp, 'cm_y', cm_y, n, 0.0_dp, 'm', error)
      if (allocated(error)) return
      call optional_reals(deck, grp, 'height', height, n, default_storey_height, 'm', error)
      if (allocated(error)) return
      g_in = given_of(grp, 'inertia', size(inertia))
      g_px = given_of(grp, 'plan_x', size(plan_x))
      g_py = given_of(grp, 'plan_y', size(plan_y))
      do f = 1, n
         idx = '('//trim(fmt_int(f))//')'
         if (g_in(f) .eqv. (g_px(f) .or. g_py(f))) then
            call bad(deck, 'floors', 'inertia'//idx, merge('given      ', '(not given)', g_in(f)), &
                     'given alone, or replaced by plan_x'//idx//' and plan_y'//idx//' (a uniform rectangle)', error)
            return
         end if
         if (g_px(f) .neqv. g_py(f)) then
            call bad(deck, 'floors', merge('plan_y', 'plan_x', g_px(f))//idx, '(not given)', &
                     'given with '//merge('plan_x', 'plan_y', g_px(f))//idx, error)
            return
         end if
         if (.not. g_in(f)) then
            call need_real(deck, 'floors', 'plan_x'//idx, plan_x(f), .true., 'm', error, positive=.true.)
            if (allocated(error)) return
            call need_real(deck, 'floors', 'plan_y'//idx, plan_y(f), .true., 'm', error, positive=.true.)
            if (allocated(error)) return
            inertia(f) = floor_inertia(mass(f), plan_x(f), plan_y(f))
         else
            call need_real(deck, 'floors', 'inertia'//idx, inertia(f), .true., 'kg m2', error, positive=.true.)
            if (allocated(error)) return
         end if
         if (height(f) < 0.0_dp) then
            call bad(deck, 'floors', 'height'//idx, trim(fmt_real(height(f))), '>= 0 m (0 = not given)', error)
            return
         end if
      end do
      call check_real(deck, 'floors', 'excitation_angle', excitation_angle, -360.0_dp, 360.0_dp, 'deg', error)
      if (allocated(error)) return
      call check_labels(deck, grp, 'floors', label, n, error)
      if (allocated(error)) return
      cfg%model%n_dof = 3*n
      allocate (cfg%model%mass(3*n), cfg%model%u0(3*n), cfg%model%v0(3*n), cfg%model%dof_label(3*n), &
                cfg%model%influence(3*n), cfg%model%floor_x(n), cfg%model%floor_y(n), &
                cfg%model%floor_height(n))
      cfg%model%u0 = 0.0_dp
      cfg%model%v0 = 0.0_dp
      c = cos(excitation_angle*acos(-1.0_dp)/180.0_dp)
      s = sin(excitation_angle*acos(-1.0_dp)/180.0_dp)
      if (modulo(excitation_angle, 90.0_dp) == 0.0_dp) then
         c = real(nint(c), dp); s = real(nint(s), dp)
      end if
      do f = 1, n
         if (len_trim(label(f)) == 0) label(f) = 'floor '//trim(fmt_int(f))
         cfg%model%mass(floor_dof(f, [1, 2, 3])) = [mass(f), mass(f), inertia(f)]
         cfg%model%influence(floor_dof(f, [1, 2, 3])) = [c, s, 0.0_dp]
         cfg%model%dof_label(floor_dof(f, 1)) = trim(label(f))//' ux'
         cfg%model%dof_label(floor_dof(f, 2)) = trim(label(f))//' uy'
         cfg%model%dof_label(floor_dof(f, 3)) = trim(label(f))//' rz'
         cfg%model%floor_x(f) = cm_x(f)
         cfg%model%floor_y(f) = cm_y(f)
      end do
      if (p_delta .and. any(height(1:n) <= 0.0_dp)) then
         f = findloc(height(1:n) <= 0.0_dp, .true., 1)
         call bad(deck, 'floors', 'height('//trim(fmt_int(f))//')', trim(fmt_real(height(f))), &
                  '> 0 m with p_delta = .true. (the geometric stiffness is the weight above over the height)', error)
         return
      end if
      cfg%model%n_floors = n
      cfg%model%floor_height = height(1:n)
      cfg%model%floor_inertia = inertia(1:n)
      cfg%model%floor_lx = merge(plan_x(1:n), 0.0_dp, .not. g_in(1:n))
      cfg%model%floor_ly = merge(plan_y(1:n), 0.0_dp, .not. g_in(1:n))
      cfg%model%p_delta = p_delta
      ! storeys: s along x (2s - 1) and along y (2s), between the floors' centres of mass
      cfg%model%n_storeys = 2*n
      allocate (cfg%model%storey_i(2*n), cfg%model%storey_j(2*n), cfg%model%storey_height(2*n), &
                cfg%model%storey_label(2*n), cfg%model%xs_storey(0), cfg%model%xs_dof(0), cfg%model%xs_coef(0), &
                cfg%model%xd_storey(0), cfg%model%xd_dev(0), cfg%model%xd_coef(0))
      do f = 1, n
         do i = 1, 2
            cfg%model%storey_i(2*f - 2 + i) = floor_dof(f, i)
            cfg%model%storey_j(2*f - 2 + i) = merge(floor_dof(f - 1, i), 0, f > 1)
            cfg%model%storey_height(2*f - 2 + i) = height(f)
            cfg%model%storey_label(2*f - 2 + i) = 'storey '//trim(fmt_int(f))//' '//merge('x', 'y', i == 1)
         end do
      end do
   end subroutine read_floors_group

   ! ---------------------------------------------------------------- &matrices
   !> A general linear structure from its matrices: K and M in Matrix Market files (the
   !> coordinate format; M diagonal, a lumped mass), the DOFs' labels, and the table
   !> motion's direction over the DOFs for &excitation (influence) and &excitation2
   !> (influence2). K becomes the stiffness entries K_x; springs, devices and dashpots join
   !> DOFs as in a model of masses.
   subroutine read_matrices_group(deck, cfg, found, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error
      character(len=path_len) :: k_file, m_file
      real(dp), allocatable :: influence(:), influence2(:)
      character(len=label_len), allocatable :: label(:)
      namelist /matrices/ k_file, m_file, label, influence, influence2
      type(group_text) :: grp
      type(sparse_matrix) :: km, mm
      character(len=512) :: msg
      character(len=:), allocatable :: path
      integer :: ios, i, n, e
      logical :: more

      k_file = ''; m_file = ''
      call find_group(deck, 'matrices', grp, found, error)
      if (allocated(error) .or. .not. found) return
      call check_lengths(deck, grp, [character(len=16) :: 'k_file', 'm_file', 'label'], [path_len, path_len, label_len - 1], &
                         error)
      if (allocated(error)) return
      ! the matrices first: their size gives the arrays' capacity
      do i = 1, 2
         call given_text(deck, grp, merge('k_file', 'm_file', i == 1), path, error)
         if (allocated(error)) return
         if (i == 1) call read_matrix_market(path, km, error)
         if (i == 2) call read_matrix_market(path, mm, error)
         if (allocated(error)) then
            error%message = deck%path//", group &matrices, "//merge('k_file', 'm_file', i == 1)//": "//error%message
            return
         end if
      end do
      n = km%n_rows
      allocate (influence(n), influence2(n), label(n), stat=ios)
      if (ios /= 0) then
         call no_memory(deck, 'matrices', n, 'DOFs', error); return
      end if
      influence = unset; influence2 = unset; label = ''
      do
         read (grp%lines, nml=matrices, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      call check_matrices(deck, km, mm, error)
      if (allocated(error)) return
      call signed_reals(deck, 'matrices', 'influence', influence, given_of(grp, 'influence', n), n, '-', error)
      if (allocated(error)) return
      call check_labels(deck, grp, 'matrices', label, n, error)
      if (allocated(error)) return
      cfg%model%n_dof = n
      allocate (cfg%model%mass(n), cfg%model%u0(n), cfg%model%v0(n))
      cfg%model%u0 = 0.0_dp
      cfg%model%v0 = 0.0_dp
      do e = 1, mm%nnz
         cfg%model%mass(mm%row(e)) = mm%val(e)
      end do
      cfg%model%dof_label = label
      cfg%model%influence = influence
      if (is_given(grp, 'influence2')) then
         call signed_reals(deck, 'matrices', 'influence2', influence2, given_of(grp, 'influence2', n), n, '-', error)
         if (allocated(error)) return
         cfg%model%influence2 = influence2
      end if
      ! K's entries on and above the diagonal
      cfg%model%n_kx = count(km%row(1:km%nnz) <= km%col(1:km%nnz))
      if (km%symmetric) cfg%model%n_kx = km%nnz
      allocate (cfg%model%kx_i(cfg%model%n_kx), cfg%model%kx_j(cfg%model%n_kx), cfg%model%kx_v(cfg%model%n_kx))
      i = 0
      do e = 1, km%nnz
         if (.not. km%symmetric .and. km%row(e) > km%col(e)) cycle
         i = i + 1
         cfg%model%kx_i(i) = min(km%row(e), km%col(e))
         cfg%model%kx_j(i) = max(km%row(e), km%col(e))
         cfg%model%kx_v(i) = km%val(e)
      end do
   end subroutine read_matrices_group

   !> K square and symmetric (a general file's K checked entry by entry, as a dense matrix up
   !> to max_dense_check DOFs), M of K's size and diagonal with masses > 0.
   subroutine check_matrices(deck, km, mm, error)
      type(deck_text), intent(in) :: deck
      type(sparse_matrix), intent(in) :: km, mm
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: a(:, :)
      integer :: n, e, i, j

      n = km%n_rows
      if (km%n_cols /= n .or. n < 1) then
         call bad(deck, 'matrices', 'k_file', trim(fmt_int(km%n_rows))//' x '//trim(fmt_int(km%n_cols)), &
                  'a square matrix', error)
         return
      end if
      if (mm%n_rows /= n .or. mm%n_cols /= n) then
         call bad(deck, 'matrices', 'm_file', trim(fmt_int(mm%n_rows))//' x '//trim(fmt_int(mm%n_cols)), &
                  "of K's size, "//trim(fmt_int(n))//' x '//trim(fmt_int(n)), error)
         return
      end if
      do e = 1, mm%nnz
         if (mm%row(e) /= mm%col(e) .and. mm%val(e) /= 0.0_dp) then
            call bad(deck, 'matrices', 'm_file', 'an entry ('//trim(fmt_int(mm%row(e)))//', '// &
                     trim(fmt_int(mm%col(e)))//') = '//trim(fmt_real(mm%val(e))), 'a diagonal (lumped) mass '// &
                     'matrix: lump a consistent mass first', error)
            return
         end if
      end do
      allocate (a(1, n))
      a = 0.0_dp
      do e = 1, mm%nnz
         if (mm%row(e) == mm%col(e)) a(1, mm%row(e)) = mm%val(e)
      end do
      do i = 1, n
         if (.not. (a(1, i) > 0.0_dp)) then
            call bad(deck, 'matrices', 'm_file', 'M('//trim(fmt_int(i))//', '//trim(fmt_int(i))//') = '// &
                     trim(fmt_real(a(1, i))), '> 0 at every DOF: a DOF without mass is condensed out of K and M '// &
                     'before (static condensation)', error)
            return
         end if
      end do
      if (km%symmetric) return
      if (n > max_dense_check) then
         call bad(deck, 'matrices', 'k_file', "a 'general' file of "//trim(fmt_int(n))//' DOFs', "a 'symmetric' "// &
                  'Matrix Market file above '//trim(fmt_int(max_dense_check))//' DOFs (scipy.io.mmwrite writes one '// &
                  'for a symmetric matrix)', error)
         return
      end if
      deallocate (a)
      allocate (a(n, n))
      a = 0.0_dp
      do e = 1, km%nnz
         a(km%row(e), km%col(e)) = km%val(e)
      end do
      do j = 1, n
         do i = j + 1, n
            if (abs(a(i, j) - a(j, i)) > 1.0e-12_dp*max(abs(a(i, j)), abs(a(j, i)))) then
               call bad(deck, 'matrices', 'k_file', 'K('//trim(fmt_int(i))//', '//trim(fmt_int(j))//') = '// &
                        trim(fmt_real(a(i, j)))//' and K('//trim(fmt_int(j))//', '//trim(fmt_int(i))//') = '// &
                        trim(fmt_real(a(j, i))), 'a symmetric stiffness (equal to 1e-12)', error)
               return
            end if
         end do
      end do
   end subroutine check_matrices

   !> K of &matrices with the springs positive definite, at every size by its banded Cholesky
   !> factor (stiffness_pivot): a mechanism or an indefinite K is named by the first DOF where
   !> the factorization fails.
   subroutine check_definite(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(in) :: cfg
      type(error_type), allocatable, intent(out) :: error
      character(len=label_len + 3) :: name
      integer :: info

      call stiffness_pivot(cfg%model, info, error)
      if (allocated(error)) return
      if (info /= 0) then
         name = ''
         if (len_trim(cfg%model%dof_label(info)) > 0) name = " '"//trim(cfg%model%dof_label(info))//"'"
         call bad(deck, 'matrices', 'k_file', 'K not positive definite at DOF '//trim(fmt_int(info))//trim(name), &
                  'the stiffness of a structure held to the table (a mechanism, or an indefinite K, fails there)', error)
      end if
   end subroutine check_definite

   !> The path of a file named by a text variable of a group (its last assignment, quoted),
   !> relative to the deck: the files are read before the group's arrays, which K sizes.
   subroutine given_text(deck, grp, var, path, error)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp
      character(len=*), intent(in) :: var
      character(len=:), allocatable, intent(out) :: path
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: item, value
      integer :: i, eq

      path = ''
      do i = size(grp%items), 1, -1
         item = grp%items(i)%s
         eq = index(item, '=')
         if (eq < 2) cycle
         if (lower(trim(adjustl(item(1:eq - 1)))) /= var) cycle
         value = trim(adjustl(item(eq + 1:)))
         if (len(value) >= 2) then
            if ((value(1:1) == "'" .or. value(1:1) == '"') .and. value(len(value):len(value)) == value(1:1)) &
               path = value(2:len(value) - 1)
         end if
         if (len(path) == 0) then
            call bad(deck, 'matrices', var, value, "a file name in quotes ('K.mtx')", error)
            return
         end if
         exit
      end do
      if (len(path) == 0) then
         call fatal_error(error, deck%path//", group &matrices: "//var//" is not given")
         return
      end if
      value = path
      call relative_to(deck%path, value, path)
   end subroutine given_text

   ! ---------------------------------------------------------------- &frames
   !> The lateral elements of a building of rigid floors: frame or wall e of storey s
   !> (between floor s and floor s - 1, 0 the ground) a shear spring k along angle in plan
   !> through the point (x, y), added to K as k b b' (fd_floors' plan_direction).
   subroutine read_frames_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      integer :: n_frames
      integer, allocatable :: storey(:)
      real(dp), allocatable :: angle(:), x(:), y(:), k(:)
      namelist /frames/ n_frames, storey, angle, x, y, k
      type(group_text) :: grp
      character(len=512) :: msg
      integer :: dof(max_plan_terms), ios, i, n, nt, m
      real(dp) :: coef(max_plan_terms), w
      real(dp), parameter :: pi = acos(-1.0_dp)
      logical :: found, more

      n_frames = unset_int
      call find_group(deck, 'frames', grp, found, error)
      if (allocated(error)) return
      if (.not. found) then
         call fatal_error(error, deck%path//": group &frames is missing: a building of &floors needs its frames")
         return
      end if
      i = array_capacity(grp, 'n_frames', max_springs)
      allocate (storey(i), angle(i), x(i), y(i), k(i), stat=ios)
      if (ios /= 0) then
         call no_memory(deck, 'frames', i, 'frames', error); return
      end if
      storey = unset_int; angle = unset; x = unset; y = unset; k = unset
      do
         read (grp%lines, nml=frames, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      call need_int(deck, grp, 'n_frames', n_frames, 0, max_springs, error)
      if (allocated(error)) return
      n = n_frames
      call plan_elements(deck, grp, cfg, n, storey, angle, x, y, error)
      if (allocated(error)) return
      call need_reals(deck, grp, 'k', k, n, 'N/m', error, positive=.true.)
      if (allocated(error)) return
      allocate (cfg%model%kx_i(0), cfg%model%kx_j(0), cfg%model%kx_v(0))
      cfg%model%n_kx = 0
      do i = 1, n
         call plan_direction(storey(i), angle(i), x(i), y(i), cfg%model%floor_x, cfg%model%floor_y, &
                             dof, coef, nt)
         call add_general_entry(cfg%model, dof(1:nt), coef(1:nt), k(i))
         ! its force k b' u along x and y in the shear of its storey
         do m = 1, 2
            w = k(i)*merge(cos(angle(i)*pi/180.0_dp), sin(angle(i)*pi/180.0_dp), m == 1)
            if (modulo(angle(i), 90.0_dp) == 0.0_dp) w = k(i)*real(nint(w/k(i)), dp)
            if (w == 0.0_dp) cycle
            cfg%model%xs_storey = [cfg%model%xs_storey, spread(2*storey(i) - 2 + m, 1, nt)]
            cfg%model%xs_dof = [cfg%model%xs_dof, dof(1:nt)]
            cfg%model%xs_coef = [cfg%model%xs_coef, w*coef(1:nt)]
         end do
      end do
   end subroutine read_frames_group

   !> The plan position of the elements of a group of a building of rigid floors: storey
   !> (1..n_floors), angle [deg], and a point (x, y) of the element's line [m].
   subroutine plan_elements(deck, grp, cfg, n, storey, angle, x, y, error)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp
      type(run_config), intent(in) :: cfg
      integer, intent(in) :: n
      integer, intent(in) :: storey(:)
      real(dp), intent(inout) :: angle(:), x(:), y(:)
      type(error_type), allocatable, intent(out) :: error

      call node_list(deck, grp, 'storey', storey, n, 1, cfg%model%n_floors, error)
      if (allocated(error)) return
      call signed_reals(deck, grp, 'angle', angle, n, 'deg', error)
      if (allocated(error)) return
      call signed_reals(deck, grp, 'x', x, n, 'm', error)
      if (allocated(error)) return
      call signed_reals(deck, grp, 'y', y, n, 'm', error)
   end subroutine plan_elements

   !> P-Delta of a building of rigid floors: the constant geometric stiffness of the gravity
   !> loads. Storey s carries the weight m_j g of every floor j >= s at that floor's centre of
   !> mass Q_j: -(m_j g / h_s) (b_x b_x' + b_y b_y') with b_x, b_y the storey's deformation at
   !> Q_j along x and y, and -(g J_j / h_s) (rz_s - rz_{s-1})^2 for the floor's mass spread
   !> about Q_j (rotational inertia J_j). Linear: the loads and the geometry do not change. The
   !> building must stay stable: the stiffness with P-Delta positive definite.
   subroutine add_p_delta(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: g = 9.80665_dp
      real(dp) :: coef(max_plan_terms), h
      real(dp), allocatable :: k(:, :)
      integer :: dof(max_plan_terms), nt, s, j, nf, info, stat

      nf = cfg%model%n_floors
      do s = 1, nf
         h = cfg%model%floor_height(s)
         do j = s, nf
            call plan_direction(s, 0.0_dp, cfg%model%floor_x(j), cfg%model%floor_y(j), cfg%model%floor_x, &
                                cfg%model%floor_y, dof, coef, nt)
            call add_general_entry(cfg%model, dof(1:nt), coef(1:nt), -cfg%model%mass(floor_dof(j, 1))*g/h)
            call plan_direction(s, 90.0_dp, cfg%model%floor_x(j), cfg%model%floor_y(j), cfg%model%floor_x, &
                                cfg%model%floor_y, dof, coef, nt)
            call add_general_entry(cfg%model, dof(1:nt), coef(1:nt), -cfg%model%mass(floor_dof(j, 1))*g/h)
            if (s > 1) then
               call add_general_entry(cfg%model, [floor_dof(s, 3), floor_dof(s - 1, 3)], [1.0_dp, -1.0_dp], &
                                      -g*cfg%model%floor_inertia(j)/h)
            else
               call add_general_entry(cfg%model, [floor_dof(s, 3)], [1.0_dp], -g*cfg%model%floor_inertia(j)/h)
            end if
         end do
      end do
      ! stable: K (the frames with P-Delta) positive definite
      allocate (k(3*nf, 3*nf), stat=stat)
      if (stat /= 0) then
         call no_memory(deck, 'floors', 3*nf, 'DOFs (the stability check of p_delta)', error); return
      end if
      call stiffness_matrix(cfg%model, k)
      call cholesky_factor(k, info)
      if (info /= 0) then
         call bad(deck, 'floors', 'p_delta', '.true.', 'for a building stable under its gravity loads: '// &
                  'its frames with P-Delta are not positive definite (buckling); stiffen the frames or '// &
                  'check mass and height', error)
      end if
   end subroutine add_p_delta

   ! ---------------------------------------------------------------- &floor_braces
   !> Braces with a friction damper at plan positions of a building of rigid floors: brace
   !> b of storey s along angle through (x, y), a device of direction b (fd_floors) that
   !> slips at slip_load. law = 'hysteretic' (default): the damper in series with a brace of
   !> the given stiffness (f = slip_load / stiffness, as &braces); 'velocity' or 'coulomb':
   !> a rigid brace (P mu = slip_load, the velocity law's band eps).
   subroutine read_floor_braces_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      integer :: n_braces
      integer, allocatable :: storey(:)
      real(dp), allocatable :: angle(:), x(:), y(:), slip_load(:), stiffness(:), eps1(:), eps(:)
      character(len=label_len), allocatable :: label(:)
      character(len=name_len), allocatable :: law(:)
      namelist /floor_braces/ n_braces, storey, angle, x, y, slip_load, stiffness, eps1, eps, law, label
      type(group_text) :: grp
      type(device_type) :: dev
      character(len=512) :: msg
      character(len=:), allocatable :: idx
      logical, allocatable :: g_k(:)
      integer :: dof(max_plan_terms), ios, i, n, nt, id, m
      real(dp) :: coef(max_plan_terms), w
      real(dp), parameter :: pi = acos(-1.0_dp)
      logical :: found, more

      n_braces = 0
      call find_group(deck, 'floor_braces', grp, found, error)
      if (allocated(error) .or. .not. found) return
      i = array_capacity(grp, 'n_braces', max_devices)
      allocate (storey(i), angle(i), x(i), y(i), slip_load(i), stiffness(i), eps1(i), eps(i), label(i), law(i), &
                stat=ios)
      if (ios /= 0) then
         call no_memory(deck, 'floor_braces', i, 'braces', error); return
      end if
      storey = unset_int; angle = unset; x = unset; y = unset; slip_load = unset; stiffness = unset
      eps1 = unset; eps = unset; label = ''; law = 'hysteretic'
      call check_length(deck, grp, 'label', label_len - 1, error)
      if (allocated(error)) return
      do
         read (grp%lines, nml=floor_braces, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      call need_int(deck, 'floor_braces', 'n_braces', n_braces, .true., 0, max_devices - cfg%model%n_devices, error)
      if (allocated(error)) return
      n = n_braces
      call plan_elements(deck, grp, cfg, n, storey, angle, x, y, error)
      if (allocated(error)) return
      call need_reals(deck, grp, 'slip_load', slip_load, n, 'N', error, positive=.true.)
      if (allocated(error)) return
      call optional_reals(deck, grp, 'eps1', eps1, n, default_eps1, 'm/s', error, positive=.true.)
      if (allocated(error)) return
      call optional_reals(deck, grp, 'eps', eps, n, default_eps, 'm/s', error, positive=.true.)
      if (allocated(error)) return
      call check_labels(deck, grp, 'floor_braces', label, n, error)
      if (allocated(error)) return
      g_k = given_of(grp, 'stiffness', size(stiffness))
      do i = 1, n
         idx = '('//trim(fmt_int(i))//')'
         call device_law(deck, 'floor_braces', i, law(i), id, error)
         if (allocated(error)) return
         if (id == law_hysteretic) then
            call need_real(deck, 'floor_braces', 'stiffness'//idx, stiffness(i), g_k(i), 'N/m', error, positive=.true.)
            if (allocated(error)) return
            call check_magnitude(deck, 'floor_braces', 'slip_load'//idx//' / stiffness'//idx, &
                                 slip_load(i)/stiffness(i), 'm', .true., error)
            if (allocated(error)) return
            dev = device_type(law=law_hysteretic, p=slip_load(i), mu=1.0_dp, eps1=eps1(i), f=slip_load(i)/stiffness(i))
         else
            if (g_k(i)) then
               call bad(deck, 'floor_braces', 'stiffness'//idx, trim(fmt_real(stiffness(i))), &
                        "not given: law"//idx//" = '"//trim(law(i))//"' has a rigid brace (law 'hysteretic' "// &
                        "takes the brace's stiffness)", error)
               return
            end if
            dev = device_type(law=id, p=slip_load(i), mu=1.0_dp, eps=eps(i), eps1=eps1(i))
         end if
         dev%label = label(i)
         if (len_trim(label(i)) == 0) dev%label = 'floor brace '//trim(fmt_int(i))
         dev%source = source_floor_brace
         dev%source_index = i
         call plan_direction(storey(i), angle(i), x(i), y(i), cfg%model%floor_x, cfg%model%floor_y, &
                             dof, coef, nt)
         call append_device(cfg%model, dev, dof(1:nt), coef(1:nt), ios)
         ! its force along x and y in the shear of its storey
         do m = 1, 2
            w = merge(cos(angle(i)*pi/180.0_dp), sin(angle(i)*pi/180.0_dp), m == 1)
            if (modulo(angle(i), 90.0_dp) == 0.0_dp) w = real(nint(w), dp)
            if (w == 0.0_dp) cycle
            cfg%model%xd_storey = [cfg%model%xd_storey, 2*storey(i) - 2 + m]
            cfg%model%xd_dev = [cfg%model%xd_dev, cfg%model%n_devices]
            cfg%model%xd_coef = [cfg%model%xd_coef, w]
         end do
      end do
   end subroutine read_floor_braces_group

   ! ---------------------------------------------------------------- &bearings
   !> Planar sliding bearings: bearing i is two devices, its components along x and y, that
   !> name each other (partner) and slide together on the resultant (fd_friction_planar). In
   !> a building of rigid floors it stands at the plan point (x, y) of storey s (between floor
   !> s and floor s - 1, the ground for s = 1); in a model of masses or matrices it joins the
   !> DOFs dof_xi, dof_yi to dof_xj, dof_yj (0: the table). p defaults, for rigid floors, to the
   !> weight of the floors it carries shared among the bearings of its storey. radius > 0: a
   !> friction pendulum, the restoring stiffness p / radius along both components.
   subroutine read_bearings_group(deck, cfg, floors, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      logical, intent(in) :: floors                      !! a building of rigid floors
      type(error_type), allocatable, intent(out) :: error
      integer :: n_bearings
      integer, allocatable :: storey(:), dof_xi(:), dof_yi(:), dof_xj(:), dof_yj(:), mu_ids(:)
      real(dp), allocatable :: x(:), y(:), p(:), mu(:), radius(:), eps(:), eps1(:), f(:), kv(:), zeta_v(:)
      real(dp), allocatable :: mu_max(:), mu_min(:), mu_rate(:), mu_table_v(:, :), mu_table_mu(:, :)
      character(len=name_len), allocatable :: law(:), mu_law(:)
      character(len=label_len), allocatable :: label(:)
      logical, allocatable :: g_mu(:), g_table(:, :), g_p(:)
      logical :: overturning
      namelist /bearings/ n_bearings, storey, x, y, dof_xi, dof_yi, dof_xj, dof_yj, law, p, mu, radius, eps, &
         eps1, f, mu_law, mu_max, mu_min, mu_rate, mu_table_v, mu_table_mu, label, overturning, kv, zeta_v
      type(group_text) :: grp
      character(len=512) :: msg
      integer :: ios, i, n, d0
      logical :: found, more

      n_bearings = 0
      overturning = .false.
      call find_group(deck, 'bearings', grp, found, error)
      if (allocated(error) .or. .not. found) return
      i = array_capacity(grp, 'n_bearings', max_devices/2)
      allocate (storey(i), dof_xi(i), dof_yi(i), dof_xj(i), dof_yj(i), x(i), y(i), p(i), mu(i), radius(i), &
                eps(i), eps1(i), f(i), law(i), kv(i), zeta_v(i), stat=ios)
      if (ios == 0) call new_mu_inputs(i, mu_law, mu_max, mu_min, mu_rate, mu_table_v, mu_table_mu, label, ios)
      if (ios /= 0) then
         call no_memory(deck, 'bearings', i, 'bearings', error); return
      end if
      storey = unset_int; dof_xi = unset_int; dof_yi = unset_int; dof_xj = unset_int; dof_yj = unset_int
      x = unset; y = unset; p = unset; mu = unset; radius = unset; eps = unset; eps1 = unset; f = unset
      kv = unset; zeta_v = unset
      law = 'velocity'
      ! a label and its components' ' x', ' y' within label_len - 1
      call check_length(deck, grp, 'label', label_len - 3, error)
      if (.not. allocated(error)) call check_length(deck, grp, 'law', name_len, error)
      if (.not. allocated(error)) call check_length(deck, grp, 'mu_law', name_len, error)
      if (allocated(error)) return
      do
         read (grp%lines, nml=bearings, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      call need_int(deck, 'bearings', 'n_bearings', n_bearings, .true., 0, (max_devices - cfg%model%n_devices)/2, &
                    error)
      if (allocated(error)) return
      n = n_bearings
      call bearing_places(deck, grp, cfg, floors, n, storey, x, y, dof_xi, dof_yi, dof_xj, dof_yj, error)
      if (allocated(error)) return
      g_mu = given_of(grp, 'mu', size(mu))
      call read_mu_laws(deck, grp, n, mu_law, mu, g_mu, mu_max, mu_min, mu_rate, mu_table_v, mu_table_mu, &
                        mu_ids, g_table, error)
      if (allocated(error)) return
      call need_reals(deck, 'bearings', 'mu', mu, g_mu, n, '', error, positive=.false.)
      if (allocated(error)) return
      g_p = given_of(grp, 'p', size(p))
      if (floors) call gravity_shares(cfg%model, n, storey, g_p, p)
      call need_reals(deck, 'bearings', 'p', p, g_p, n, 'N', error, positive=.true.)
      if (allocated(error)) return
      call slider_settings(deck, grp, 'bearings', n, radius, eps, eps1, f, error)
      if (allocated(error)) return
      call check_labels(deck, grp, 'bearings', label, n, error)
      if (allocated(error)) return
      call vertical_supports(deck, grp, n, kv, zeta_v, error)
      if (allocated(error)) return
      d0 = cfg%model%n_devices
      do i = 1, n
         call add_bearing(deck, cfg, floors, i, storey(i), x(i), y(i), [dof_xi(i), dof_yi(i), dof_xj(i), dof_yj(i)], &
                          law(i), p(i), mu(i), radius(i), eps(i), eps1(i), f(i), label(i), mu_ids(i), mu_min(i), &
                          mu_rate(i), mu_table_v(:, i), mu_table_mu(:, i), g_table(:, i), error)
         if (allocated(error)) return
         cfg%model%dev(d0 + 2*i - 1:d0 + 2*i)%kv = kv(i)
         cfg%model%dev(d0 + 2*i - 1:d0 + 2*i)%zeta_v = zeta_v(i)
      end do
      if (overturning) call bearings_overturning(deck, cfg, floors, n, d0, storey, x, y, error)
   end subroutine read_bearings_group

   !> The bearings' vertical supports: kv >= 0 N/m (0, the default: rigid) and the damping ratio
   !> 0 <= zeta_v < 1 (default 0) of the vertical oscillator of each bearing's share of the mass.
   subroutine vertical_supports(deck, grp, n, kv, zeta_v, error)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp
      integer, intent(in) :: n
      real(dp), intent(inout) :: kv(:), zeta_v(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: i

      call optional_reals(deck, 'bearings', 'kv', kv, given_of(grp, 'kv', size(kv)), n, 0.0_dp, 'N/m', error)
      if (allocated(error)) return
      call optional_reals(deck, 'bearings', 'zeta_v', zeta_v, given_of(grp, 'zeta_v', size(zeta_v)), n, 0.0_dp, &
                          '', error)
      if (allocated(error)) return
      do i = 1, n
         if (kv(i) < 0.0_dp) then
            call bad(deck, 'bearings', 'kv('//trim(fmt_int(i))//')', trim(fmt_real(kv(i))), &
                     '>= 0 N/m (0 = a rigid vertical support)', error)
            return
         end if
         if (zeta_v(i) < 0.0_dp .or. zeta_v(i) >= 1.0_dp) then
            call bad(deck, 'bearings', 'zeta_v('//trim(fmt_int(i))//')', trim(fmt_real(zeta_v(i))), &
                     'in 0 <= zeta_v < 1 (a ratio of critical damping)', error)
            return
         end if
      end do
   end subroutine vertical_supports

   !> overturning = .true.: the bearings' normal forces take the overturning moments of the
   !> floors they carry (fd_overturning), which needs the storey heights of a building of rigid
   !> floors above each storey of bearings and, in each such storey, bearings not all on one line.
   subroutine bearings_overturning(deck, cfg, floors, n, d0, storey, x, y, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      logical, intent(in) :: floors                      !! a building of rigid floors
      integer, intent(in) :: n                           !! bearings
      integer, intent(in) :: d0                          !! devices before the bearings
      integer, intent(in) :: storey(:)
      real(dp), intent(in) :: x(:), y(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: i, f, bad_storey

      if (.not. floors) then
         call bad(deck, 'bearings', 'overturning', '.true.', '.false. in a model of masses or matrices: the '// &
                  'overturning takes the floors'' masses at their storey heights (a building of rigid floors, &floors)', &
                  error)
         return
      end if
      if (n == 0) return
      do i = 1, n
         do f = storey(i) + 1, cfg%model%n_floors
            if (cfg%model%floor_height(f) > 0.0_dp) cycle
            call bad(deck, 'bearings', 'overturning', '.true.', 'given with the storey heights of the floors the '// &
                     'bearings carry: height('//trim(fmt_int(f))//') of &floors is '// &
                     trim(fmt_real(cfg%model%floor_height(f)))//' (not given); give it > 0 m', error)
            return
         end do
      end do
      allocate (cfg%model%ot_arm(2, n))
      call overturning_arms(storey(1:n), x(1:n), y(1:n), cfg%model%ot_arm, bad_storey)
      if (bad_storey /= 0) then
         call bad(deck, 'bearings', 'overturning', '.true.', 'given with bearings not all on one line in each '// &
                  'storey: those of storey = '//trim(fmt_int(bad_storey))//' are one or on a line, which shares '// &
                  'no overturning moment about it', error)
         return
      end if
      cfg%model%overturning = .true.
      cfg%model%ot_storey = storey(1:n)
      cfg%model%ot_dev = [(d0 + 2*i - 1, i=1, n)]
   end subroutine bearings_overturning

   !> Where the bearings stand: storey, x, y (rigid floors) or their four DOFs (other models);
   !> the variables of the other kind refused.
   subroutine bearing_places(deck, grp, cfg, floors, n, storey, x, y, dof_xi, dof_yi, dof_xj, dof_yj, error)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp
      type(run_config), intent(in) :: cfg
      logical, intent(in) :: floors
      integer, intent(in) :: n
      integer, intent(inout) :: storey(:), dof_xi(:), dof_yi(:), dof_xj(:), dof_yj(:)
      real(dp), intent(inout) :: x(:), y(:)
      type(error_type), allocatable, intent(out) :: error
      character(len=8), parameter :: plan(3) = [character(len=8) :: 'storey', 'x', 'y']
      character(len=8), parameter :: dofs(4) = [character(len=8) :: 'dof_xi', 'dof_yi', 'dof_xj', 'dof_yj']
      integer :: k

      do k = 1, merge(4, 3, floors)
         if (floors) then
            if (.not. is_given(grp, trim(dofs(k)))) cycle
            call bad(deck, 'bearings', trim(dofs(k)), '(given)', 'not given in a building of rigid floors (&floors): '// &
                     'a bearing stands at a plan point, storey, x and y', error)
         else
            if (.not. is_given(grp, trim(plan(k)))) cycle
            call bad(deck, 'bearings', trim(plan(k)), '(given)', 'given only for a building of rigid floors '// &
                     '(&floors): a bearing of a model of masses or matrices joins dof_xi, dof_yi to dof_xj, dof_yj', error)
         end if
         return
      end do
      if (floors) then
         call node_list(deck, 'bearings', 'storey', storey, given_of(grp, 'storey', size(storey)), n, 1, &
                        cfg%model%n_floors, error)
         if (allocated(error)) return
         call signed_reals(deck, 'bearings', 'x', x, given_of(grp, 'x', size(x)), n, 'm', error)
         if (allocated(error)) return
         call signed_reals(deck, 'bearings', 'y', y, given_of(grp, 'y', size(y)), n, 'm', error)
         return
      end if
      call node_list(deck, 'bearings', 'dof_xi', dof_xi, given_of(grp, 'dof_xi', size(dof_xi)), n, 1, &
                     cfg%model%n_dof, error)
      if (.not. allocated(error)) call node_list(deck, 'bearings', 'dof_yi', dof_yi, &
                                                 given_of(grp, 'dof_yi', size(dof_yi)), n, 1, cfg%model%n_dof, error)
      if (.not. allocated(error)) call node_list(deck, 'bearings', 'dof_xj', dof_xj, &
                                                 given_of(grp, 'dof_xj', size(dof_xj)), n, 0, cfg%model%n_dof, error)
      if (.not. allocated(error)) call node_list(deck, 'bearings', 'dof_yj', dof_yj, &
                                                 given_of(grp, 'dof_yj', size(dof_yj)), n, 0, cfg%model%n_dof, error)
   end subroutine bearing_places

   !> The normal force of the bearings not given one: the weight g sum m_f of the floors
   !> f >= s above storey s, shared equally among the bearings of that storey.
   pure subroutine gravity_shares(model, n, storey, g_p, p)
      type(model_type), intent(in) :: model
      integer, intent(in) :: n
      integer, intent(in) :: storey(:)
      logical, intent(inout) :: g_p(:)
      real(dp), intent(inout) :: p(:)
      real(dp), parameter :: g = 9.80665_dp
      integer :: i, f

      do i = 1, n
         if (g_p(i) .or. storey(i) < 1 .or. storey(i) > model%n_floors) cycle
         p(i) = 0.0_dp
         do f = storey(i), model%n_floors
            p(i) = p(i) + g*model%mass(floor_dof(f, 1))
         end do
         p(i) = p(i)/count(storey(1:n) == storey(i))
         g_p(i) = .true.
      end do
   end subroutine gravity_shares

   !> Bearing i as its two components (x, then y) and, curved, its pendulum's stiffness p / R
   !> along each.
   subroutine add_bearing(deck, cfg, floors, i, storey, x, y, dofs, law, p, mu, radius, eps, eps1, f, label, &
                          mu_id, mu_min, mu_rate, tab_v, tab_mu, g_table, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      logical, intent(in) :: floors
      integer, intent(in) :: i, storey, dofs(4), mu_id
      real(dp), intent(in) :: x, y, p, mu, radius, eps, eps1, f, mu_min, mu_rate, tab_v(:), tab_mu(:)
      character(len=*), intent(in) :: law, label
      logical, intent(in) :: g_table(:)
      type(error_type), allocatable, intent(out) :: error
      type(device_type) :: dev
      character(len=:), allocatable :: idx
      integer :: dof(max_plan_terms), nt, m, id, ios, d0
      real(dp) :: coef(max_plan_terms)

      idx = '('//trim(fmt_int(i))//')'
      call device_law(deck, 'bearings', i, law, id, error)
      if (allocated(error)) return
      if (id /= law_velocity .and. id /= law_hysteretic .and. id /= law_coulomb) then
         call bad(deck, 'bearings', 'law'//idx, "'"//trim(law)//"'", "'velocity', 'hysteretic' or 'coulomb' "// &
                  "(technique = 'moreau_jean'): the laws a planar bearing has", error)
         return
      end if
      if (p*mu /= 0.0_dp .and. p*mu < min_scale) then
         call bad(deck, 'bearings', 'p'//idx//' * mu'//idx, trim(fmt_real(p*mu)), '0 (no friction) or at least '// &
                  trim(fmt_real(min_scale))//' N: the friction force P mu of a bearing', error)
         return
      end if
      if (radius < 0.0_dp) then
         call bad(deck, 'bearings', 'radius'//idx, trim(fmt_real(radius)), '>= 0 m (0 = flat)', error)
         return
      end if
      if (radius > 0.0_dp) then
         call check_magnitude(deck, 'bearings', 'radius'//idx, radius, 'm', .true., error)
         if (.not. allocated(error)) call check_magnitude(deck, 'bearings', 'p'//idx//' / radius'//idx, p/radius, &
                                                          'N/m', .true., error)
         if (allocated(error)) return
      end if
      if (.not. floors) then
         if (dofs(1) == dofs(3) .or. dofs(2) == dofs(4) .or. dofs(1) == dofs(2) .or. &
             (dofs(3) == dofs(4) .and. dofs(3) > 0)) then
            call bad(deck, 'bearings', 'dof_xi'//idx//', dof_yi'//idx//', dof_xj'//idx//', dof_yj'//idx, &
                     trim(fmt_int(dofs(1)))//', '//trim(fmt_int(dofs(2)))//', '//trim(fmt_int(dofs(3)))//', '// &
                     trim(fmt_int(dofs(4))), 'dof_xi /= dof_yi, dof_xi /= dof_xj, dof_yi /= dof_yj, and '// &
                     'dof_xj /= dof_yj unless both are 0 (the table)', error)
            return
         end if
      end if
      dev = device_type(law=id, p=p, mu=mu, eps=eps, eps1=eps1, f=f, radius=radius, p_static=p)
      call apply_mu_law(deck, 'bearings', i, mu_id, mu_min, mu_rate, tab_v, tab_mu, g_table, dev, error)
      if (allocated(error)) return
      dev%source = source_bearing
      dev%source_index = i
      d0 = cfg%model%n_devices
      do m = 1, 2
         dev%component = m
         dev%partner = d0 + 3 - m
         dev%label = trim(label)//merge(' x', ' y', m == 1)
         if (len_trim(label) == 0) dev%label = 'bearing '//trim(fmt_int(i))//merge(' x', ' y', m == 1)
         if (floors) then
            call plan_direction(storey, merge(0.0_dp, 90.0_dp, m == 1), x, y, cfg%model%floor_x, cfg%model%floor_y, &
                                dof, coef, nt)
         else
            nt = 1
            dof(1) = dofs(m)
            coef(1) = 1.0_dp
            if (dofs(m + 2) > 0) then
               nt = 2
               dof(2) = dofs(m + 2)
               coef(2) = -1.0_dp
            end if
         end if
         call append_device(cfg%model, dev, dof(1:nt), coef(1:nt), ios)
         if (floors) then
            ! its force along x or y in the shear of its storey
            cfg%model%xd_storey = [cfg%model%xd_storey, 2*storey - 2 + m]
            cfg%model%xd_dev = [cfg%model%xd_dev, cfg%model%n_devices]
            cfg%model%xd_coef = [cfg%model%xd_coef, 1.0_dp]
            if (radius > 0.0_dp) then   ! and its pendulum's restoring force (p / R) b' u
               cfg%model%xs_storey = [cfg%model%xs_storey, spread(2*storey - 2 + m, 1, nt)]
               cfg%model%xs_dof = [cfg%model%xs_dof, dof(1:nt)]
               cfg%model%xs_coef = [cfg%model%xs_coef, (p/radius)*coef(1:nt)]
            end if
         end if
         if (radius > 0.0_dp) call pendulum_stiffness(deck, cfg, floors, dof(1:nt), coef(1:nt), p/radius, error)
         if (allocated(error)) return
      end do
   end subroutine add_bearing

   !> A friction pendulum's restoring stiffness k along a component of direction (dof, coef):
   !> a spring between its two DOFs (a model of masses or matrices), or K_x's entries k b b'
   !> (rigid floors).
   subroutine pendulum_stiffness(deck, cfg, floors, dof, coef, k, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      logical, intent(in) :: floors
      integer, intent(in) :: dof(:)
      real(dp), intent(in) :: coef(:), k
      type(error_type), allocatable, intent(out) :: error
      integer :: j

      if (floors) then
         call add_general_entry(cfg%model, dof, coef, k)
         return
      end if
      if (cfg%model%n_springs + 1 > max_springs) then
         call bad(deck, 'bearings', 'n_bearings', trim(fmt_int(cfg%model%n_devices/2)), 'such that the springs of '// &
                  'the curved bearings and the others are at most '//trim(fmt_int(max_springs)), error)
         return
      end if
      j = 0
      if (size(dof) == 2) j = dof(2)
      cfg%model%spring_i = [cfg%model%spring_i, dof(1)]
      cfg%model%spring_j = [cfg%model%spring_j, j]
      cfg%model%spring_k = [cfg%model%spring_k, k]
      cfg%model%spring_source = [cfg%model%spring_source, source_bearing]
      cfg%model%n_springs = cfg%model%n_springs + 1
   end subroutine pendulum_stiffness

   ! ---------------------------------------------------------------- &braces
   !> Friction dampers in series with an elastic brace (Pall type), a shorthand: brace b
   !> becomes a hysteretic device with P mu = slip_load (p = slip_load, mu = 1) and
   !> f = slip_load / stiffness, so that its sticking stiffness P mu / f is the brace's.
   subroutine read_braces_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      integer :: n_braces
      integer, allocatable :: node_i(:), node_j(:)
      real(dp), allocatable :: slip_load(:), stiffness(:), eps1(:)
      character(len=label_len), allocatable :: label(:)
      namelist /braces/ n_braces, node_i, node_j, slip_load, stiffness, eps1, label
      type(group_text) :: grp
      type(device_type), allocatable :: dev(:)
      character(len=512) :: msg
      character(len=:), allocatable :: idx
      integer :: ios, i, n
      logical :: found, more

      n_braces = 0
      call find_group(deck, 'braces', grp, found, error)
      if (allocated(error) .or. .not. found) return
      i = array_capacity(grp, 'n_braces', max_devices)
      allocate (node_i(i), node_j(i), slip_load(i), stiffness(i), eps1(i), label(i), stat=ios)
      if (ios /= 0) then
         call no_memory(deck, 'braces', i, 'braces', error); return
      end if
      node_i = unset_int; node_j = unset_int; slip_load = unset; stiffness = unset; eps1 = unset; label = ''
      ! a longer label would be cut by the namelist read: refused from the group's text first
      call check_length(deck, grp, 'label', label_len - 1, error)
      if (allocated(error)) return
      do
         read (grp%lines, nml=braces, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      call need_int(deck, 'braces', 'n_braces', n_braces, .true., 0, max_devices - cfg%model%n_devices, error)
      if (allocated(error)) return
      n = n_braces
      call node_list(deck, grp, 'node_i', node_i, n, 1, cfg%model%n_dof, error)
      if (allocated(error)) return
      call node_list(deck, grp, 'node_j', node_j, n, 0, cfg%model%n_dof, error)
      if (allocated(error)) return
      call need_reals(deck, grp, 'slip_load', slip_load, n, 'N', error, positive=.true.)
      if (allocated(error)) return
      call need_reals(deck, grp, 'stiffness', stiffness, n, 'N/m', error, positive=.true.)
      if (allocated(error)) return
      call optional_reals(deck, grp, 'eps1', eps1, n, default_eps1, 'm/s', error, positive=.true.)
      if (allocated(error)) return
      call check_labels(deck, grp, 'braces', label, n, error)
      if (allocated(error)) return
      allocate (dev(n))
      do i = 1, n
         idx = '('//trim(fmt_int(i))//')'
         call distinct_nodes(deck, 'braces', i, node_i(i), node_j(i), 'a brace joins two different nodes', error)
         if (allocated(error)) return
         ! the sticking displacement f = slip_load / stiffness, a length: within the limits
         call check_magnitude(deck, 'braces', 'slip_load'//idx//' / stiffness'//idx, slip_load(i)/stiffness(i), &
                              'm', .true., error)
         if (allocated(error)) return
         dev(i) = device_type(node_i=node_i(i), node_j=node_j(i), law=law_hysteretic, p=slip_load(i), &
                              mu=1.0_dp, eps1=eps1(i), f=slip_load(i)/stiffness(i))
         dev(i)%label = label(i)
         if (len_trim(label(i)) == 0) dev(i)%label = 'brace '//trim(fmt_int(i))
         dev(i)%source = source_brace
         dev(i)%source_index = i
      end do
      cfg%model%dev = [cfg%model%dev, dev]
      cfg%model%n_devices = size(cfg%model%dev)
   end subroutine read_braces_group

   ! ---------------------------------------------------------------- &isolators
   !> Sliding isolators, a shorthand: isolator i (flat, or curved with radius R) becomes a
   !> friction device with the normal force P = weight (its law and mu as in &friction) and,
   !> when curved, a spring weight / radius between the same nodes (the pendulum's
   !> restoring stiffness W / R, small displacements).
   subroutine read_isolators_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      integer :: n_isolators
      integer, allocatable :: node_i(:), node_j(:)
      character(len=name_len), allocatable :: law(:)
      real(dp), allocatable :: weight(:), mu(:), radius(:), eps(:), eps1(:), f(:)
      character(len=name_len), allocatable :: mu_law(:)
      real(dp), allocatable :: mu_max(:), mu_min(:), mu_rate(:), mu_table_v(:, :), mu_table_mu(:, :)
      character(len=label_len), allocatable :: label(:)
      integer, allocatable :: mu_ids(:)
      logical, allocatable :: g_mu(:), g_table(:, :)
      namelist /isolators/ n_isolators, node_i, node_j, law, weight, mu, radius, eps, eps1, f, &
         mu_law, mu_max, mu_min, mu_rate, mu_table_v, mu_table_mu, label
      type(group_text) :: grp
      type(device_type), allocatable :: dev(:)
      character(len=512) :: msg
      character(len=:), allocatable :: idx
      integer :: ios, i, n, id
      logical :: found, more

      n_isolators = 0
      call find_group(deck, 'isolators', grp, found, error)
      if (allocated(error) .or. .not. found) return
      i = array_capacity(grp, 'n_isolators', max_devices)
      allocate (node_i(i), node_j(i), law(i), weight(i), mu(i), radius(i), eps(i), eps1(i), f(i), stat=ios)
      if (ios == 0) call new_mu_inputs(i, mu_law, mu_max, mu_min, mu_rate, mu_table_v, mu_table_mu, label, ios)
      if (ios /= 0) then
         call no_memory(deck, 'isolators', i, 'isolators', error); return
      end if
      node_i = unset_int; node_j = unset_int; law = ''
      weight = unset; mu = unset; radius = unset; eps = unset; eps1 = unset; f = unset
      ! a longer label would be cut by the namelist read: refused from the group's text first
      call check_lengths(deck, grp, [character(len=16) :: 'label', 'law', 'mu_law'], [label_len - 1, name_len, name_len], &
                         error)
      if (allocated(error)) return
      do
         read (grp%lines, nml=isolators, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      call need_int(deck, 'isolators', 'n_isolators', n_isolators, .true., 0, max_devices - cfg%model%n_devices, &
                    error)
      if (allocated(error)) return
      n = n_isolators
      call node_list(deck, grp, 'node_i', node_i, n, 1, cfg%model%n_dof, error)
      if (allocated(error)) return
      call node_list(deck, grp, 'node_j', node_j, n, 0, cfg%model%n_dof, error)
      if (allocated(error)) return
      call need_reals(deck, grp, 'weight', weight, n, 'N', error, positive=.true.)
      if (allocated(error)) return
      g_mu = given_of(grp, 'mu', size(mu))
      call read_mu_laws(deck, grp, n, mu_law, mu, g_mu, mu_max, mu_min, mu_rate, mu_table_v, mu_table_mu, &
                        mu_ids, g_table, error)
      if (allocated(error)) return
      call need_reals(deck, 'isolators', 'mu', mu, g_mu, n, '', error, positive=.false.)
      if (allocated(error)) return
      call slider_settings(deck, grp, 'isolators', n, radius, eps, eps1, f, error)
      if (allocated(error)) return
      call check_labels(deck, grp, 'isolators', label, n, error)
      if (allocated(error)) return
      if (any(law(n + 1:) /= '')) then
         call bad(deck, 'isolators', 'law', 'with '//trim(fmt_int(findloc(law /= '', .true., 1, back=.true.))) &
                  //' values', 'at most n_isolators = '//trim(fmt_int(n))//' values', error)
         return
      end if
      allocate (dev(n))
      do i = 1, n
         idx = '('//trim(fmt_int(i))//')'
         call distinct_nodes(deck, 'isolators', i, node_i(i), node_j(i), 'an isolator joins two different nodes', error)
         if (allocated(error)) return
         if (radius(i) < 0.0_dp) then
            call bad(deck, 'isolators', 'radius'//idx, trim(fmt_real(radius(i))), '>= 0 m (0 = flat)', error)
            return
         end if
         if (radius(i) > 0.0_dp) then
            call check_magnitude(deck, 'isolators', 'radius'//idx, radius(i), 'm', .true., error)
            if (allocated(error)) return
            ! the pendulum's stiffness W / R is a spring: within the magnitude limits
            call check_magnitude(deck, 'isolators', 'weight'//idx//' / radius'//idx, weight(i)/radius(i), 'N/m', &
                                 .true., error)
            if (allocated(error)) return
         end if
         if (weight(i)*mu(i) /= 0.0_dp .and. weight(i)*mu(i) < min_scale) then
            call bad(deck, 'isolators', 'weight'//idx//' * mu'//idx, trim(fmt_real(weight(i)*mu(i))), &
                     '0 (no friction) or at least '//trim(fmt_real(min_scale))//' N: the friction force W mu of '// &
                     'an isolator (here W = '//trim(fmt_real(weight(i)))//' N, mu = '//trim(fmt_real(mu(i)))//')', error)
            return
         end if
         call device_law(deck, 'isolators', i, law(i), id, error)
         if (allocated(error)) return
         dev(i) = device_type(node_i=node_i(i), node_j=node_j(i), law=id, p=weight(i), mu=mu(i), &
                              eps=eps(i), eps1=eps1(i), f=f(i))
         call apply_mu_law(deck, 'isolators', i, mu_ids(i), mu_min(i), mu_rate(i), mu_table_v(:, i), &
                           mu_table_mu(:, i), g_table(:, i), dev(i), error)
         if (allocated(error)) return
         dev(i)%label = label(i)
         if (len_trim(label(i)) == 0) dev(i)%label = 'isolator '//trim(fmt_int(i))
         dev(i)%source = source_isolator
         dev(i)%source_index = i
         if (radius(i) > 0.0_dp) then
            ! the restoring stiffness of the curved surface, W / R
            if (cfg%model%n_springs + 1 > max_springs) then
               call bad(deck, 'isolators', 'n_isolators', trim(fmt_int(n)), 'such that the springs of the '// &
                        'curved isolators and those of &springs are at most '//trim(fmt_int(max_springs)), error)
               return
            end if
            cfg%model%spring_i = [cfg%model%spring_i, node_i(i)]
            cfg%model%spring_j = [cfg%model%spring_j, node_j(i)]
            cfg%model%spring_k = [cfg%model%spring_k, weight(i)/radius(i)]
            cfg%model%spring_source = [cfg%model%spring_source, source_isolator]
            cfg%model%n_springs = cfg%model%n_springs + 1
         end if
      end do
      cfg%model%dev = [cfg%model%dev, dev]
      cfg%model%n_devices = size(cfg%model%dev)
   end subroutine read_isolators_group

   !> A sliding device's settings that have defaults (&isolators, &bearings): the surface's
   !> radius, the velocity law's eps, the hysteretic law's eps1 and f.
   subroutine slider_settings(deck, grp, group, n, radius, eps, eps1, f, error)
      type(deck_text), intent(in) :: deck                 !! the deck
      type(group_text), intent(in) :: grp                 !! the group's text
      character(len=*), intent(in) :: group               !! its name
      integer, intent(in) :: n                            !! the devices it defines
      real(dp), intent(inout) :: radius(:), eps(:), eps1(:), f(:) !! read, defaults where not given
      type(error_type), allocatable, intent(out) :: error !! a value out of range, named

      call optional_reals(deck, group, 'radius', radius, given_of(grp, 'radius', size(radius)), n, &
                          default_radius, 'm', error)
      if (allocated(error)) return
      call optional_reals(deck, group, 'eps', eps, given_of(grp, 'eps', size(eps)), n, default_eps, 'm/s', &
                          error, positive=.true.)
      if (allocated(error)) return
      call optional_reals(deck, group, 'eps1', eps1, given_of(grp, 'eps1', size(eps1)), n, default_eps1, &
                          'm/s', error, positive=.true.)
      if (allocated(error)) return
      call optional_reals(deck, group, 'f', f, given_of(grp, 'f', size(f)), n, default_f, 'm', error, &
                          positive=.true.)
   end subroutine slider_settings

   ! ---------------------------------------------------------------- &storeys
   !> The storeys whose drift and shear the outputs report: each a pair of nodes (upper
   !> node_i, lower node_j) or the two nodes of a spring of &springs, with an optional
   !> height (for the drift ratio) and label.
   subroutine read_storeys_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      integer :: n_storeys
      integer, allocatable :: node_i(:), node_j(:), spring(:)
      real(dp), allocatable :: height(:)
      character(len=label_len), allocatable :: label(:)
      logical, allocatable :: g_i(:), g_j(:), g_spring(:)
      namelist /storeys/ n_storeys, node_i, node_j, spring, height, label
      type(group_text) :: grp
      character(len=512) :: msg
      character(len=:), allocatable :: idx
      integer :: ios, i, n, last
      logical :: found, more

      n_storeys = 0
      cfg%model%n_storeys = 0
      allocate (cfg%model%storey_i(0), cfg%model%storey_j(0), cfg%model%storey_height(0), &
                cfg%model%storey_label(0))
      call find_group(deck, 'storeys', grp, found, error)
      if (allocated(error) .or. .not. found) return
      i = array_capacity(grp, 'n_storeys', max_dof)
      allocate (node_i(i), node_j(i), spring(i), height(i), label(i), stat=ios)
      if (ios /= 0) then
         call no_memory(deck, 'storeys', i, 'storeys', error); return
      end if
      node_i = unset_int; node_j = unset_int; spring = unset_int; height = unset; label = ''
      ! a longer label would be cut by the namelist read: refused from the group's text first
      call check_length(deck, grp, 'label', label_len - 1, error)
      if (allocated(error)) return
      do
         read (grp%lines, nml=storeys, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, error)
         if (.not. more) exit
      end do
      if (allocated(error)) return
      call need_int(deck, 'storeys', 'n_storeys', n_storeys, .true., 0, max_dof, error)
      if (allocated(error)) return
      n = n_storeys
      g_i = given_of(grp, 'node_i', size(node_i))
      g_j = given_of(grp, 'node_j', size(node_j))
      g_spring = given_of(grp, 'spring', size(spring))
      do i = 1, n
         idx = '('//trim(fmt_int(i))//')'
         if (g_spring(i)) then
            if (g_i(i) .or. g_j(i)) then
               call bad(deck, 'storeys', 'spring'//idx, trim(fmt_int(spring(i))), 'given alone: storey '// &
                        trim(fmt_int(i))//' is a spring or a pair of nodes (node_i'//idx//', node_j'//idx// &
                        '), not both', error)
               return
            end if
            if (spring(i) < 1 .or. spring(i) > cfg%model%n_springs) then
               call bad(deck, 'storeys', 'spring'//idx, trim(fmt_int(spring(i))), 'a spring in 1..'// &
                        trim(fmt_int(cfg%model%n_springs)), error)
               return
            end if
            node_i(i) = cfg%model%spring_i(spring(i))
            node_j(i) = cfg%model%spring_j(spring(i))
            g_i(i) = .true.; g_j(i) = .true.
         end if
      end do
      last = findloc(g_spring, .true., 1, back=.true.)
      if (last > n) then
         call bad(deck, 'storeys', 'spring('//trim(fmt_int(last))//')', trim(fmt_int(spring(last))), &
                  'absent: only '//trim(fmt_int(n))//' value(s) are expected', error)
         return
      end if
      call node_list(deck, 'storeys', 'node_i', node_i, g_i, n, 1, cfg%model%n_dof, error)
      if (allocated(error)) return
      call node_list(deck, 'storeys', 'node_j', node_j, g_j, n, 0, cfg%model%n_dof, error)
      if (allocated(error)) return
      call optional_reals(deck, grp, 'height', height, n, default_storey_height, 'm', error)
      if (allocated(error)) return
      call check_labels(deck, grp, 'storeys', label, n, error)
      if (allocated(error)) return
      do i = 1, n
         idx = '('//trim(fmt_int(i))//')'
         call distinct_nodes(deck, 'storeys', i, node_i(i), node_j(i), 'a storey lies between two different nodes', error)
         if (allocated(error)) return
         if (height(i) < 0.0_dp) then
            call bad(deck, 'storeys', 'height'//idx, trim(fmt_real(height(i))), '>= 0 m (0 = not given)', error)
            return
         end if
         if (height(i) > 0.0_dp) then
            call check_magnitude(deck, 'storeys', 'height'//idx, height(i), 'm', .true., error)
            if (allocated(error)) return
         end if
      end do
      cfg%model%n_storeys = n
      cfg%model%storey_i = node_i(1:n)
      cfg%model%storey_j = node_j(1:n)
      cfg%model%storey_height = height(1:n)
      cfg%model%storey_label = label(1:n)
   end subroutine read_storeys_group

   ! ---------------------------------------------------------------- mu(v), labels
   !> The inputs of velocity-dependent friction and labels, unset.
   subroutine new_mu_inputs(m, mu_law, mu_max, mu_min, mu_rate, mu_table_v, mu_table_mu, label, stat)
      integer, intent(in) :: m                 !! items the arrays hold (array_capacity)
      character(len=name_len), allocatable, intent(out) :: mu_law(:)
      real(dp), allocatable, intent(out) :: mu_max(:), mu_min(:), mu_rate(:), mu_table_v(:, :), mu_table_mu(:, :)
      character(len=label_len), allocatable, intent(out) :: label(:)
      integer, intent(out) :: stat             !! 0, or the allocation's failure

      allocate (mu_law(m), mu_max(m), mu_min(m), mu_rate(m), mu_table_v(max_mu_points, m), &
                mu_table_mu(max_mu_points, m), label(m), stat=stat)
      if (stat /= 0) return
      mu_law = ''; mu_max = unset; mu_min = unset; mu_rate = unset; mu_table_v = unset; mu_table_mu = unset
      label = ''
   end subroutine new_mu_inputs

   !> mu as a function of the sliding velocity for each of n items of a group: mu_law
   !> ('constant' by default), and for 'exponential' mu_max, mu_min, mu_rate, for 'table' the
   !> points (mu_table_v(k, i), mu_table_mu(k, i)). For those two, mu is not given: it is set
   !> here to mu_max, or to the table's last value (what a slide at high speed meets).
   subroutine read_mu_laws(deck, grp, n, mu_law, mu, g_mu, mu_max, mu_min, mu_rate, tab_v, tab_mu, ids, g_table, &
                           error)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp      !! the group read (what it gives)
      integer, intent(in) :: n
      character(len=name_len), intent(in) :: mu_law(:)
      real(dp), intent(inout) :: mu(:)
      logical, intent(inout) :: g_mu(:)        !! the elements of mu given (or set here)
      real(dp), intent(inout) :: mu_max(:), mu_min(:), mu_rate(:)
      real(dp), intent(in) :: tab_v(:, :), tab_mu(:, :)
      integer, allocatable, intent(out) :: ids(:)
      logical, allocatable, intent(out) :: g_table(:, :)   !! the points of the tables given
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: idx, choices, law_of, group
      logical, allocatable :: g_max(:), g_min(:), g_rate(:), g_tv(:, :), g_tm(:, :)
      integer :: i, k, np, last

      group = grp%name
      g_max = given_of(grp, 'mu_max', size(mu_max))
      g_min = given_of(grp, 'mu_min', size(mu_min))
      g_rate = given_of(grp, 'mu_rate', size(mu_rate))
      g_tv = reshape(given_of(grp, 'mu_table_v', size(tab_v), shape(tab_v)), shape(tab_v))
      g_tm = reshape(given_of(grp, 'mu_table_mu', size(tab_mu), shape(tab_mu)), shape(tab_mu))
      g_table = g_tv .or. g_tm
      allocate (ids(n))
      last = findloc(mu_law /= '', .true., 1, back=.true.)
      if (last > n) then
         call bad(deck, group, 'mu_law('//trim(fmt_int(last))//')', "'"//trim(mu_law(last))//"'", &
                  'absent: only '//trim(fmt_int(n))//' value(s) are expected', error)
         return
      end if
      do k = 1, 3
         select case (k)
         case (1)
            call no_extra(deck, group, 'mu_max', mu_max, g_max, n, error)
         case (2)
            call no_extra(deck, group, 'mu_min', mu_min, g_min, n, error)
         case (3)
            call no_extra(deck, group, 'mu_rate', mu_rate, g_rate, n, error)
         end select
         if (allocated(error)) return
      end do
      do i = n + 1, size(tab_v, 2)
         if (any(g_table(:, i))) then
            call bad(deck, group, trim(table_var(i))//'(:, '//trim(fmt_int(i))//')', '(given)', &
                     'absent: only '//trim(fmt_int(n))//' item(s) are expected', error)
            return
         end if
      end do
      do i = 1, n
         idx = '('//trim(fmt_int(i))//')'
         ids(i) = default_mu_law
         if (len_trim(mu_law(i)) > 0) ids(i) = keyword_id(mu_laws, mu_law(i))
         if (ids(i) == 0) then
            call keyword_choices(mu_laws, choices)
            call bad(deck, group, 'mu_law'//idx, "'"//trim(mu_law(i))//"'", 'one of '//choices, error)
            return
         end if
         law_of = "mu_law"//idx//" = '"//trim(mu_laws(ids(i))%name)//"'"
         ! what the chosen form does not use must not be given (a forgotten mu_law)
         if (ids(i) /= mu_exponential) then
            if (g_max(i)) then
               call bad(deck, group, 'mu_max'//idx, trim(fmt_real(mu_max(i))), "absent with "//law_of// &
                        " (set mu_law"//idx//" = 'exponential' to use it)", error); return
            end if
            if (g_min(i)) then
               call bad(deck, group, 'mu_min'//idx, trim(fmt_real(mu_min(i))), "absent with "//law_of// &
                        " (set mu_law"//idx//" = 'exponential' to use it)", error); return
            end if
            if (g_rate(i)) then
               call bad(deck, group, 'mu_rate'//idx, trim(fmt_real(mu_rate(i))), "absent with "//law_of// &
                        " (set mu_law"//idx//" = 'exponential' to use it)", error); return
            end if
         end if
         if (ids(i) /= mu_table) then
            if (any(g_table(:, i))) then
               call bad(deck, group, trim(table_var(i))//'(:, '//trim(fmt_int(i))//')', '(given)', "absent with "//law_of// &
                        " (set mu_law"//idx//" = 'table' to use it)", error); return
            end if
         end if
         if (ids(i) == mu_constant) cycle
         if (g_mu(i)) then
            call bad(deck, group, 'mu'//idx, trim(fmt_real(mu(i))), "absent with "//law_of//": mu(v) is given by "// &
                     trim(mu_laws(ids(i))%note), error)
            return
         end if
         select case (ids(i))
         case (mu_exponential)
            call need_real(deck, group, 'mu_max'//idx, mu_max(i), g_max(i), '', error, positive=.false.)
            if (allocated(error)) return
            call need_real(deck, group, 'mu_min'//idx, mu_min(i), g_min(i), '', error, positive=.false.)
            if (allocated(error)) return
            call need_real(deck, group, 'mu_rate'//idx, mu_rate(i), g_rate(i), 's/m', error, positive=.true.)
            if (allocated(error)) return
            mu(i) = mu_max(i)
            g_mu(i) = .true.
         case (mu_table)
            np = 0
            do k = 1, size(tab_v, 1)
               if (.not. g_table(k, i)) exit
               np = k
            end do
            if (any(g_table(np + 1:, i))) then
               call bad(deck, group, 'mu_table_v(:, '//trim(fmt_int(i))//')', '(with a gap)', &
                        'points 1, 2, ... without a gap', error)
               return
            end if
            if (np < 2) then
               call bad(deck, group, 'mu_table_v(:, '//trim(fmt_int(i))//')', '('//trim(fmt_int(np))//' point(s))', &
                        'at least 2 points (v, mu), at most '//trim(fmt_int(max_mu_points)), error)
               return
            end if
            do k = 1, np
               idx = '('//trim(fmt_int(k))//', '//trim(fmt_int(i))//')'
               call need_real(deck, group, 'mu_table_v'//idx, tab_v(k, i), g_tv(k, i), 'm/s', error, positive=.false.)
               if (allocated(error)) return
               call need_real(deck, group, 'mu_table_mu'//idx, tab_mu(k, i), g_tm(k, i), '', error, positive=.false.)
               if (allocated(error)) return
            end do
            do k = 2, np
               if (tab_v(k, i) <= tab_v(k - 1, i)) then
                  call bad(deck, group, 'mu_table_v('//trim(fmt_int(k))//', '//trim(fmt_int(i))//')', &
                           trim(fmt_real(tab_v(k, i))), '> mu_table_v('//trim(fmt_int(k - 1))//', '// &
                           trim(fmt_int(i))//') = '//trim(fmt_real(tab_v(k - 1, i)))//': velocities increase', error)
                  return
               end if
            end do
            mu(i) = tab_mu(np, i)
            g_mu(i) = .true.
         end select
      end do
   contains
      !> The table variable given for item i, as a message names it.
      pure function table_var(i) result(name)
         integer, intent(in) :: i
         character(len=11) :: name
         name = merge('mu_table_v ', 'mu_table_mu', any(g_tv(:, i)))
      end function table_var
   end subroutine read_mu_laws

   !> Set a device's mu(v) from the checked inputs (read_mu_laws); an error when the form
   !> is not constant and the device's law is not the velocity law.
   subroutine apply_mu_law(deck, group, i, id, mu_min, mu_rate, tab_v, tab_mu, g_table, dev, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group
      integer, intent(in) :: i, id
      real(dp), intent(in) :: mu_min, mu_rate, tab_v(:), tab_mu(:)
      logical, intent(in) :: g_table(:)        !! the points given (1 to the table's last)
      type(device_type), intent(inout) :: dev
      type(error_type), allocatable, intent(out) :: error
      integer :: k

      dev%mu_law = id
      if (id == mu_constant) return
      if (.not. law_mu_of_speed(dev%law)) then
         call bad(deck, group, 'mu_law('//trim(fmt_int(i))//')', "'"//trim(mu_laws(id)%name)//"'", &
                  "'constant' with law("//trim(fmt_int(i))//") = '"//trim(law_name(dev%law))//"': "// &
                  "velocity-dependent friction is available for the velocity law only (docs/theory.md, 5.4)", error)
         return
      end if
      select case (id)
      case (mu_exponential)
         dev%mu_min = mu_min
         dev%mu_rate = mu_rate
      case (mu_table)
         dev%n_mu_points = 0
         do k = 1, size(tab_v)
            if (.not. g_table(k)) exit
            dev%n_mu_points = k
            dev%mu_v(k) = tab_v(k)
            dev%mu_at(k) = tab_mu(k)
         end do
      end select
   end subroutine apply_mu_law

   !> Labels: at most n given; each at most label_len characters (longer ones are cut by the
   !> reader: refused here when the last character is used, as a likely cut).
   subroutine check_labels(deck, grp, group, label, n, error)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp
      character(len=*), intent(in) :: group
      character(len=label_len), intent(in) :: label(:)
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      integer :: last, i

      ! a longer string would be cut by the namelist reader: refused from the group's text
      call check_length(deck, grp, 'label', label_len - 1, error)
      if (allocated(error)) return
      last = findloc(label /= '', .true., 1, back=.true.)
      if (last > n) then
         call bad(deck, group, 'label('//trim(fmt_int(last))//')', "'"//trim(label(last))//"'", &
                  'absent: only '//trim(fmt_int(n))//' value(s) are expected', error)
         return
      end if
      do i = 1, n
         if (label(i)(label_len:label_len) /= ' ') then
            call bad(deck, group, 'label('//trim(fmt_int(i))//')', "'"//label(i)//"...'", 'at most '// &
                     trim(fmt_int(label_len - 1))//' characters long', error)
            return
         end if
         if (index(label(i), '"') > 0 .or. index(label(i), '\') > 0 .or. index(label(i), ',') > 0) then
            call bad(deck, group, 'label('//trim(fmt_int(i))//')', "'"//trim(label(i))//"'", &
                     'free of the characters " \ and , (labels name columns and plots)', error)
            return
         end if
      end do
   end subroutine check_labels

   ! ---------------------------------------------------------------- damping from modes
   !> 'rayleigh' damping as the ratio xi at two natural modes (mode_i, mode_j of the stuck or
   !> the free system) instead of a0, a1: checked here, resolved by resolve_rayleigh once the
   !> devices are known.
   subroutine rayleigh_modes(deck, xi, a0, a1, mode_i, mode_j, given_i, given_j, mode_system, cfg, error)
      type(deck_text), intent(in) :: deck
      real(dp), intent(in) :: xi, a0, a1
      integer, intent(in) :: mode_i, mode_j
      logical, intent(in) :: given_i, given_j     !! the deck gives mode_i, mode_j
      character(len=*), intent(in) :: mode_system
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      integer :: sys

      cfg%model%mode_i = 0
      cfg%model%mode_j = 0
      if (.not. given_i .and. .not. given_j) then
         ! xi with 'rayleigh' is a ratio at two modes: without them it would be left unused
         ! and the structure damped by a0, a1 alone (undamped when they are not given)
         if (xi /= default_xi) call bad(deck, 'damping', 'xi', trim(fmt_real(xi)), "absent with 'rayleigh' "// &
                                        "damping unless mode_i and mode_j are given (xi is the ratio at those "// &
                                        "two modes); or give rayleigh_a0 and rayleigh_a1 alone", error)
         return
      end if
      if (.not. given_i .or. .not. given_j) then
         call fatal_error(error, deck%path//", group &damping: "//trim(merge('mode_i', 'mode_j', .not. given_i))// &
                          " is not given: 'rayleigh' damping from modes needs xi, mode_i and mode_j")
         return
      end if
      if (a0 /= 0.0_dp .or. a1 /= 0.0_dp) then
         call bad(deck, 'damping', merge('rayleigh_a0', 'rayleigh_a1', a0 /= 0.0_dp), trim(fmt_real(merge(a0, a1, &
                  a0 /= 0.0_dp))), 'absent with mode_i, mode_j: give either rayleigh_a0 and rayleigh_a1, or xi '// &
                  'with mode_i and mode_j', error)
         return
      end if
      if (mode_i < 1) then
         call bad(deck, 'damping', 'mode_i', trim(fmt_int(mode_i)), '>= 1 (1 = the first mode)', error); return
      end if
      if (mode_j < 1) then
         call bad(deck, 'damping', 'mode_j', trim(fmt_int(mode_j)), '>= 1 (1 = the first mode)', error); return
      end if
      call check_real(deck, 'damping', 'xi', xi, 0.0_dp, 1.0_dp, '', error, open_hi=.true.)
      if (allocated(error)) return
      call keyword_value(deck, 'damping', 'mode_system', mode_systems, mode_system, sys, error)
      if (allocated(error)) return
      cfg%model%mode_i = mode_i
      cfg%model%mode_j = mode_j
      cfg%model%mode_system = sys
   end subroutine rayleigh_modes

   !> a0 = 2 xi wi wj / (wi + wj), a1 = 2 xi / (wi + wj): the Rayleigh damping with the ratio
   !> xi at the circular frequencies wi, wj of modes mode_i, mode_j of the chosen system.
   subroutine resolve_rayleigh(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      type(modes_type) :: modes
      real(dp), allocatable :: k(:, :), c(:, :)
      real(dp) :: wi, wj
      character(len=:), allocatable :: sys
      integer :: n, mi, mj, bad_mode, stat

      if (cfg%model%damping /= damping_rayleigh .or. cfg%model%mode_i == 0) return
      n = cfg%model%n_dof
      mi = cfg%model%mode_i
      mj = cfg%model%mode_j
      if (n > modes_dense_dofs) then
         ! a large model: no n x n matrix (fd_modes' subspace iteration on the elements)
         call natural_modes_sparse(cfg%model, 0.0_dp, 0.0_dp, cfg%model%mode_system, max(mi, mj), modes, error)
      else
         allocate (k(n, n), c(n, n), stat=stat)
         if (stat /= 0) then
            call fatal_error(error, deck%path//", group &damping: not enough memory for the modes of "// &
                             trim(fmt_int(n))//" DOFs (mode_i, mode_j)", stat_no_memory)
            return
         end if
         c = 0.0_dp
         call stiffness_matrix(cfg%model, k)
         call natural_modes(cfg%model, k, c, cfg%model%mode_system, max(mi, mj), modes, error)
      end if
      if (allocated(error)) then
         error%message = deck%path//", group &damping: the modes for mode_i, mode_j: "//error%message
         return
      end if
      sys = "of the "//trim(mode_systems(cfg%model%mode_system)%name)//" system"
      if (max(mi, mj) > modes%nq) then
         call bad(deck, 'damping', merge('mode_j', 'mode_i', mj > mi), trim(fmt_int(max(mi, mj))), &
                  '<= '//trim(fmt_int(modes%nq))//', the number of modes '//sys//" (mode_system = '"// &
                  trim(mode_systems(cfg%model%mode_system)%name)//"')", error)
         return
      end if
      bad_mode = 0
      if (modes%omega2(mj) <= 0.0_dp) bad_mode = mj
      if (modes%omega2(mi) <= 0.0_dp) bad_mode = mi
      if (bad_mode > 0) then
         call bad(deck, 'damping', merge('mode_i', 'mode_j', bad_mode == mi), trim(fmt_int(bad_mode)), &
                  'a mode with a finite period: mode '//trim(fmt_int(bad_mode))//' '//sys// &
                  ' is a rigid-body mode (w = 0)', error)
         return
      end if
      wi = sqrt(modes%omega2(mi))
      wj = sqrt(modes%omega2(mj))
      cfg%model%rayleigh_a0 = 2.0_dp*cfg%model%xi*wi*wj/(wi + wj)
      cfg%model%rayleigh_a1 = 2.0_dp*cfg%model%xi/(wi + wj)
      ! the factors found are held to the limits of given ones
      call check_magnitude(deck, 'damping', 'rayleigh_a0 (from xi, mode_i, mode_j)', cfg%model%rayleigh_a0, '1/s', &
                           .false., error)
      if (.not. allocated(error)) call check_magnitude(deck, 'damping', 'rayleigh_a1 (from xi, mode_i, mode_j)', &
                                                       cfg%model%rayleigh_a1, 's', .false., error)
   end subroutine resolve_rayleigh

   ! ---------------------------------------------------------------- helpers
   !> Size of a group's arrays, from the count the group declares (`count_var`, read from its
   !> assignment before the namelist read): twice the count and a few more, so that a list of
   !> extra values is reported by no_extra, and memory follows the deck, not the capacity
   !> limit; 16 when the count is absent, unreadable or outside 0..limit (the checks after
   !> the read report it).
   pure integer function array_capacity(grp, count_var, limit) result(cap)
      type(group_text), intent(in) :: grp     !! the group
      character(len=*), intent(in) :: count_var !! its count variable (lower case)
      integer, intent(in) :: limit            !! largest count allowed
      character(len=:), allocatable :: item
      integer :: i, eq, n, ios

      cap = 16
      do i = size(grp%items), 1, -1         ! the last assignment counts, as in a namelist read
         item = grp%items(i)%s
         eq = index(item, '=')
         if (eq < 2) cycle
         if (lower(trim(adjustl(item(1:eq - 1)))) /= count_var) cycle
         read (item(eq + 1:), *, iostat=ios) n
         if (ios == 0 .and. n >= 0 .and. n <= limit) cap = 2*n + 16
         return
      end do
   end function array_capacity

   !> The text of a group the deck must have (find_group), or an error saying it is missing.
   subroutine required_group(deck, group, grp, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group               !! group name, lower case
      type(group_text), intent(out) :: grp                !! the group's text
      type(error_type), allocatable, intent(out) :: error !! missing, or find_group's error
      logical :: found
      call find_group(deck, group, grp, found, error)
      if (allocated(error) .or. found) return
      call fatal_error(error, deck%path//": required group &"//group//" is missing")
   end subroutine required_group

   !> Item i of a group joins two different nodes.
   subroutine distinct_nodes(deck, group, i, node_i, node_j, rule, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group
      integer, intent(in) :: i                            !! the item
      integer, intent(in) :: node_i, node_j               !! its nodes
      character(len=*), intent(in) :: rule                !! what the item is, for the message
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: idx
      if (node_i /= node_j) return
      idx = '('//trim(fmt_int(i))//')'
      call bad(deck, group, 'node_j'//idx, trim(fmt_int(node_j)), 'different from node_i'//idx//' = '// &
               trim(fmt_int(node_i))//': '//rule, error)
   end subroutine distinct_nodes

   !> The id of law(i) of a device (fd_names), or an error naming the choices.
   subroutine device_law(deck, group, i, law, id, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group
      integer, intent(in) :: i                            !! the device (item) of the group
      character(len=*), intent(in) :: law                 !! its law as given, blank if not
      integer, intent(out) :: id                          !! the law's id
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: choices, idx
      id = law_id(law)
      if (id /= 0) return
      call law_choices(choices)
      idx = '('//trim(fmt_int(i))//')'
      if (len_trim(law) == 0) then
         call bad(deck, group, 'law'//idx, '(not given)', 'one of '//choices, error)
      else
         call bad(deck, group, 'law'//idx, "'"//trim(law)//"'", 'one of '//choices, error)
      end if
   end subroutine device_law

   !> The id of `text` in the keyword table `table` (fd_names), or an error naming the group,
   !> the variable, the value and the choices.
   subroutine keyword_value(deck, group, var, table, text, id, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var, text
      type(keyword_type), intent(in) :: table(:)
      integer, intent(out) :: id
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: choices

      id = keyword_id(table, text)
      if (id /= 0) return
      call keyword_choices(table, choices)
      call bad(deck, group, var, "'"//trim(text)//"'", 'one of '//choices, error)
   end subroutine keyword_value

   subroutine bad(deck, group, var, val, must, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var, val, must
      type(error_type), allocatable, intent(out) :: error
      call fatal_error(error, deck%path//", group &"//group//": "//var//" = "//val//" is invalid: must be "//must)
   end subroutine bad

   !> Memory for a group's arrays of n entries cannot be had.
   subroutine no_memory(deck, group, n, what, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, what
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      call fatal_error(error, deck%path//", group &"//group//": not enough memory to read "//trim(fmt_int(n))// &
                       " entries of "//what, stat_no_memory)
   end subroutine no_memory

   !> A string longer than its variable's capacity is an error, found in the group's text
   !> before the namelist read (which would cut it, and warn under -fcheck).
   subroutine check_length(deck, grp, var, cap, error)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp
      character(len=*), intent(in) :: var
      integer, intent(in) :: cap
      type(error_type), allocatable, intent(out) :: error
      integer :: length, line
      call longest_string(grp, var, length, line)
      if (length <= cap) return
      call fatal_error(error, deck%path//", group &"//grp%name//", line "//trim(fmt_int(line))//": "//var// &
                       " is a string of "//trim(fmt_int(length))//" characters: must be at most "// &
                       trim(fmt_int(cap))//" characters long")
   end subroutine check_length

   !> check_length of several variables, in their order: the first too long is the error.
   subroutine check_lengths(deck, grp, vars, caps, error)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp
      character(len=*), intent(in) :: vars(:)             !! the variables, lower case
      integer, intent(in) :: caps(:)                      !! the capacity of each
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      do k = 1, size(vars)
         call check_length(deck, grp, trim(vars(k)), caps(k), error)
         if (allocated(error)) return
      end do
   end subroutine check_lengths

   !> The value a group's variable has after its read, when the group's text gives one; "not
   !> given" is read from the text (given_elements), never from a value.
   pure logical function is_given(grp, var)
      type(group_text), intent(in) :: grp
      character(len=*), intent(in) :: var     !! a scalar variable, lower case
      logical :: g(1)
      call given_elements(grp, var, [1], g)
      is_given = g(1)
   end function is_given

   !> The elements of an array variable (n of them, of shape `extents` when not 1-D) that the
   !> group's text gives, in array element order.
   pure function given_of(grp, var, n, extents) result(g)
      type(group_text), intent(in) :: grp
      character(len=*), intent(in) :: var     !! the variable, lower case
      integer, intent(in) :: n                !! its size
      integer, intent(in), optional :: extents(:) !! its shape (default [n])
      logical, allocatable :: g(:)
      allocate (g(n))
      if (present(extents)) then
         call given_elements(grp, var, extents, g)
      else
         call given_elements(grp, var, [n], g)
      end if
   end function given_of

   !> need_int of the group's count variable var, given or not as the group's text says.
   subroutine need_int_of(deck, grp, var, x, lo, hi, error)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp                 !! the group's text
      character(len=*), intent(in) :: var                 !! the variable, lower case
      integer, intent(in) :: x, lo, hi
      type(error_type), allocatable, intent(out) :: error
      call need_int_named(deck, grp%name, var, x, is_given(grp, var), lo, hi, error)
   end subroutine need_int_of

   !> need_reals of the group's array var, with the elements its text gives.
   subroutine need_reals_of(deck, grp, var, x, n, unit, error, positive)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp                 !! the group's text
      character(len=*), intent(in) :: var, unit
      real(dp), intent(in) :: x(:)
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in) :: positive
      call need_reals_named(deck, grp%name, var, x, given_of(grp, var, size(x)), n, unit, error, positive)
   end subroutine need_reals_of

   !> optional_reals of the group's array var, with the elements its text gives.
   subroutine optional_reals_of(deck, grp, var, x, n, default, unit, error, positive)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp                 !! the group's text
      character(len=*), intent(in) :: var, unit
      real(dp), intent(inout) :: x(:)
      integer, intent(in) :: n
      real(dp), intent(in) :: default
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: positive
      call optional_reals_named(deck, grp%name, var, x, given_of(grp, var, size(x)), n, default, unit, error, &
                                positive)
   end subroutine optional_reals_of

   !> signed_reals of the group's array var, with the elements its text gives.
   subroutine signed_reals_of(deck, grp, var, x, n, unit, error)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp                 !! the group's text
      character(len=*), intent(in) :: var, unit
      real(dp), intent(in) :: x(:)
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      call signed_reals_named(deck, grp%name, var, x, given_of(grp, var, size(x)), n, unit, error)
   end subroutine signed_reals_of

   !> node_list of the group's array var, with the elements its text gives.
   subroutine node_list_of(deck, grp, var, x, n, lo, hi, error)
      type(deck_text), intent(in) :: deck
      type(group_text), intent(in) :: grp                 !! the group's text
      character(len=*), intent(in) :: var
      integer, intent(in) :: x(:), n, lo, hi
      type(error_type), allocatable, intent(out) :: error
      call node_list_named(deck, grp%name, var, x, given_of(grp, var, size(x)), n, lo, hi, error)
   end subroutine node_list_of

   subroutine need_int_named(deck, group, var, x, given, lo, hi, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var
      integer, intent(in) :: x, lo, hi
      logical, intent(in) :: given                        !! the deck gives x
      type(error_type), allocatable, intent(out) :: error
      if (.not. given) then
         call fatal_error(error, deck%path//", group &"//group//": "//var//" is not given"); return
      end if
      if (x < lo .or. x > hi) &
         call bad(deck, group, var, trim(fmt_int(x)), 'in '//trim(fmt_int(lo))//'..'//trim(fmt_int(hi)), error)
   end subroutine need_int_named

   subroutine need_real(deck, group, var, x, given, unit, error, positive)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var, unit
      real(dp), intent(in) :: x
      logical, intent(in) :: given                        !! the deck gives x
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: positive
      logical :: pos
      pos = .true.
      if (present(positive)) pos = positive
      if (.not. given) then
         call fatal_error(error, deck%path//", group &"//group//": "//var//" is not given"); return
      end if
      if (.not. ieee_is_finite(x)) then
         call bad(deck, group, var, trim(fmt_real(x)), 'a finite number', error); return
      end if
      if (pos .and. x <= 0.0_dp) then
         call bad(deck, group, var, trim(fmt_real(x)), '> 0 '//unit, error)
      else if (.not. pos .and. x < 0.0_dp) then
         call bad(deck, group, var, trim(fmt_real(x)), '>= 0 '//unit, error)
      else
         call check_magnitude(deck, group, var, x, unit, pos, error)
      end if
   end subroutine need_real

   !> |x| at most max_magnitude; and at least min_scale when x must be > 0 (or is not 0).
   subroutine check_magnitude(deck, group, var, x, unit, scale, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var, unit
      real(dp), intent(in) :: x
      logical, intent(in) :: scale                 !! x is a scale: small values are checked too
      type(error_type), allocatable, intent(out) :: error
      if (abs(x) > max_magnitude) then
         call bad(deck, group, var, trim(fmt_real(x)), 'at most '//trim(fmt_real(max_magnitude))//' '//trim(unit)// &
                  ' in magnitude (larger values overflow the products a run forms)', error)
      else if (scale .and. abs(x) < min_scale) then
         call bad(deck, group, var, trim(fmt_real(x)), 'at least '//trim(fmt_real(min_scale))//' '//trim(unit)// &
                  ' in magnitude (smaller values make the steps and products of a run meaningless)', error)
      end if
   end subroutine check_magnitude

   subroutine check_real(deck, group, var, x, lo, hi, unit, error, open_lo, open_hi)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var, unit
      real(dp), intent(in) :: x, lo, hi
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: open_lo, open_hi
      logical :: olo, ohi, ok
      character(len=:), allocatable :: range
      olo = .false.; ohi = .false.
      if (present(open_lo)) olo = open_lo
      if (present(open_hi)) ohi = open_hi
      ok = ieee_is_finite(x)
      if (ok) ok = merge(x > lo, x >= lo, olo) .and. merge(x < hi, x <= hi, ohi)
      if (ok) then
         call check_magnitude(deck, group, var, x, unit, .false., error)
         return
      end if
      range = merge('(', '[', olo)//trim(fmt_real(lo))//', '
      if (hi >= max_magnitude) then
         range = range//trim(fmt_real(max_magnitude))//']'
      else
         range = range//trim(fmt_real(hi))//merge(')', ']', ohi)
      end if
      call bad(deck, group, var, trim(fmt_real(x)), 'in '//range//' '//unit, error)
   end subroutine check_real

   !> n values must be given, finite and > 0 (or >= 0); no more than n.
   subroutine need_reals_named(deck, group, var, x, given, n, unit, error, positive)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var, unit
      real(dp), intent(in) :: x(:)
      logical, intent(in) :: given(:)                     !! the elements the deck gives
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in) :: positive
      integer :: i
      do i = 1, n
         call need_real(deck, group, var//'('//trim(fmt_int(i))//')', x(i), given(i), unit, error, positive)
         if (allocated(error)) return
      end do
      call no_extra(deck, group, var, x, given, n, error)
   end subroutine need_reals_named

   !> Values that must be given, finite and of either sign (a plan coordinate, an angle).
   subroutine signed_reals_named(deck, group, var, x, given, n, unit, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var, unit
      real(dp), intent(in) :: x(:)
      logical, intent(in) :: given(:)                     !! the elements the deck gives
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: name
      integer :: i
      do i = 1, n
         name = var//'('//trim(fmt_int(i))//')'
         if (.not. given(i)) then
            call fatal_error(error, deck%path//", group &"//group//": "//name//" is not given"); return
         end if
         if (.not. ieee_is_finite(x(i))) then
            call bad(deck, group, name, trim(fmt_real(x(i))), 'a finite number', error); return
         end if
         call check_magnitude(deck, group, name, abs(x(i)), unit, .false., error)
         if (allocated(error)) return
      end do
      call no_extra(deck, group, var, x, given, n, error)
   end subroutine signed_reals_named

   !> Values not given take a default; given ones must be finite (and > 0 if positive).
   subroutine optional_reals_named(deck, group, var, x, given, n, default, unit, error, positive)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var, unit
      real(dp), intent(inout) :: x(:)
      logical, intent(in) :: given(:)                     !! the elements the deck gives
      integer, intent(in) :: n
      real(dp), intent(in) :: default
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: positive
      integer :: i
      logical :: pos
      pos = .false.
      if (present(positive)) pos = positive
      do i = 1, n
         if (.not. given(i)) x(i) = default
         if (.not. ieee_is_finite(x(i))) then
            call bad(deck, group, var//'('//trim(fmt_int(i))//')', trim(fmt_real(x(i))), 'a finite number', error); return
         end if
         if (pos .and. x(i) <= 0.0_dp) then
            call bad(deck, group, var//'('//trim(fmt_int(i))//')', trim(fmt_real(x(i))), '> 0 '//unit, error); return
         end if
         call check_magnitude(deck, group, var//'('//trim(fmt_int(i))//')', x(i), unit, pos, error)
         if (allocated(error)) return
      end do
      call no_extra(deck, group, var, x, given, n, error)
   end subroutine optional_reals_named

   subroutine no_extra(deck, group, var, x, given, n, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var
      real(dp), intent(in) :: x(:)
      logical, intent(in) :: given(:)                     !! the elements the deck gives
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      integer :: last
      last = findloc(given, .true., 1, back=.true.)
      if (last > n) call bad(deck, group, var//'('//trim(fmt_int(last))//')', trim(fmt_real(x(last))), &
                             'absent: only '//trim(fmt_int(n))//' value(s) are expected', error)
   end subroutine no_extra

   subroutine node_list_named(deck, group, var, x, given, n, lo, hi, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var
      integer, intent(in) :: x(:), n, lo, hi
      logical, intent(in) :: given(:)                     !! the elements the deck gives
      type(error_type), allocatable, intent(out) :: error
      integer :: i, last
      do i = 1, n
         if (.not. given(i)) then
            call fatal_error(error, deck%path//", group &"//group//": "//var//'('//trim(fmt_int(i))//") is not given")
            return
         end if
         if (x(i) < lo .or. x(i) > hi) then
            call bad(deck, group, var//'('//trim(fmt_int(i))//')', trim(fmt_int(x(i))), 'a node in '//trim(fmt_int(lo))//'..'// &
                     trim(fmt_int(hi))//merge(' (0 = table)', '            ', lo == 0), error)
            return
         end if
      end do
      last = findloc(given, .true., 1, back=.true.)
      if (last > n) call bad(deck, group, var//'('//trim(fmt_int(last))//')', trim(fmt_int(x(last))), &
                             'absent: only '//trim(fmt_int(n))//' value(s) are expected', error)
   end subroutine node_list_named

   !> A path relative to the directory of the deck (absolute paths are kept).
   pure subroutine relative_to(deck_path, path, full)
      character(len=*), intent(in) :: deck_path, path
      character(len=:), allocatable, intent(out) :: full
      integer :: slash
      if (path(1:1) == '/') then
         full = path
         return
      end if
      slash = index(deck_path, '/', back=.true.)
      full = deck_path(1:slash)//path
   end subroutine relative_to

   !> File name of the deck without its directory and extension.
   pure subroutine stem(path, name)
      character(len=*), intent(in) :: path
      character(len=*), intent(out) :: name
      integer :: slash, dot
      slash = index(path, '/', back=.true.)
      name = path(slash + 1:)
      dot = index(name, '.', back=.true.)
      if (dot > 1) name = name(1:dot - 1)
   end subroutine stem

end module fd_deck
