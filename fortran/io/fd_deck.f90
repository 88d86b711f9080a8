!> The deck reader: one namelist deck is one run. Groups &model, &springs, &damping and
!> &excitation are required; &friction, &integration and &output are optional. Every value
!> is validated after reading, and the model against the technique chosen; messages name
!> the file, the group, the variable and the value. Keywords, their lists in messages and
!> every default come from fd_names. docs/namelist.md documents every variable.
module fd_deck
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use, intrinsic :: ieee_exceptions, only: ieee_set_halting_mode, ieee_support_halting, ieee_overflow, &
                                            ieee_set_flag
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real, stat_no_memory
   use fd_textio, only: lower
   use fd_namelist, only: deck_text, group_text, load_deck, deck_from_string, find_group, group_item, &
                          group_read_error, check_groups, longest_string
   use fd_names, only: keyword_id, keyword_choices, law_id, law_choices, &
                       damping_types, damping_stiffness, damping_rayleigh, damping_none, &
                       excitation_types, excitation_harmonic, excitation_record, excitation_none, &
                       record_kinds, record_displacement, techniques, technique_name, &
                       default_u0, default_v0, default_xi, default_period, default_rayleigh_a0, &
                       default_rayleigh_a1, default_n_devices, default_eps, default_eps1, default_f, &
                       default_ramp_cycles, default_record_kind, default_record_scale, default_technique, &
                       default_beta, default_gamma, default_n1, default_n2, default_n, default_theta, &
                       default_check_correctness, default_dt_min, default_dir, default_output_every, &
                       default_write_history
   use fd_model, only: model_type, integration_type, device_type, output_type
   use fd_excitation, only: excitation_type
   use fd_record, only: read_record, record_info, record_formats, record_units_list, units_factor
   use fd_technique, only: check_technique
   use fd_step_limits, only: check_step_limits
   use fd_names, only: technique_newmark
   implicit none
   private

   public :: run_config, read_deck, read_deck_string, max_dof, max_springs, max_devices

   integer, parameter :: max_dof = 10000      !! capacity of the DOF arrays of a deck
   integer, parameter :: max_springs = 40000  !! capacity of the spring arrays
   integer, parameter :: max_devices = 10000  !! capacity of the device arrays
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
   end type run_config

contains

   !> Read and validate a deck file.
   subroutine read_deck(path, cfg, error)
      character(len=*), intent(in) :: path                !! deck file
      type(run_config), intent(out) :: cfg                !! what it defines
      type(error_type), allocatable, intent(out) :: error !! first problem found
      type(deck_text) :: deck

      ! a value too large for a double ('1e400' in a deck or a record) overflows to infinity
      ! when it is converted, and is then rejected with a message: a build that traps
      ! overflow (-ffpe-trap, tools/test_checked.sh) must not stop there. The halting mode is
      ! restored when this reader returns (Fortran 2008, 14.3), the overflow handled.
      if (ieee_support_halting(ieee_overflow)) call ieee_set_halting_mode(ieee_overflow, .false.)
      call load_deck(path, deck, error)
      if (.not. allocated(error)) call read_groups(deck, cfg, error)
      call ieee_set_flag(ieee_overflow, .false.)
   end subroutine read_deck

   !> Read and validate a deck given as text. The path names the deck in messages, gives
   !> the default output name, and is the base of a relative record_file.
   subroutine read_deck_string(text, path, cfg, error)
      character(len=*), intent(in) :: text                !! the deck, lines separated by newlines
      character(len=*), intent(in) :: path                !! name of the deck
      type(run_config), intent(out) :: cfg                !! what it defines
      type(error_type), allocatable, intent(out) :: error !! first problem found
      type(deck_text) :: deck

      ! a value too large for a double ('1e400' in a deck or a record) overflows to infinity
      ! when it is converted, and is then rejected with a message: a build that traps
      ! overflow (-ffpe-trap, tools/test_checked.sh) must not stop there. The halting mode is
      ! restored when this reader returns (Fortran 2008, 14.3), the overflow handled.
      if (ieee_support_halting(ieee_overflow)) call ieee_set_halting_mode(ieee_overflow, .false.)
      call deck_from_string(text, path, deck, error)
      if (.not. allocated(error)) call read_groups(deck, cfg, error)
      call ieee_set_flag(ieee_overflow, .false.)
   end subroutine read_deck_string

   subroutine read_groups(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error

      cfg%deck_path = deck%path
      call check_groups(deck, [character(len=12) :: 'model', 'springs', 'damping', 'friction', &
                               'excitation', 'integration', 'output'], error)
      if (allocated(error)) return
      call read_model_group(deck, cfg, error)
      if (allocated(error)) return
      call read_springs_group(deck, cfg, error)
      if (allocated(error)) return
      call read_damping_group(deck, cfg, error)
      if (allocated(error)) return
      call read_friction_group(deck, cfg, error)
      if (allocated(error)) return
      call read_excitation_group(deck, cfg, error)
      if (allocated(error)) return
      call read_integration_group(deck, cfg, error)
      if (allocated(error)) return
      call read_output_group(deck, cfg, error)
      if (allocated(error)) return
      ! what the technique cannot integrate (a law, a table motion)
      call check_technique(cfg%model, cfg%exc, cfg%opts, error)
      if (allocated(error)) then
         error%message = deck%path//", "//error%message
         return
      end if
      ! Newmark's steps: bounded work, digits left in the effective stiffness
      if (cfg%opts%technique == technique_newmark) call check_step_limits(cfg%model, cfg%exc, cfg%opts, error)
      if (allocated(error)) error%message = deck%path//", "//error%message
   end subroutine read_groups

   ! ---------------------------------------------------------------- &model
   subroutine read_model_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      integer :: n_dof
      real(dp), allocatable :: mass(:), u0(:), v0(:)
      namelist /model/ n_dof, mass, u0, v0
      type(group_text) :: grp
      character(len=512) :: msg, msg0
      character(len=:), allocatable :: rec
      integer :: ios, i, n
      logical :: found

      n_dof = unset_int
      allocate (mass(max_dof), u0(max_dof), v0(max_dof))
      mass = unset; u0 = unset; v0 = unset
      call find_group(deck, 'model', grp, found, error)
      if (allocated(error)) return
      if (.not. found) then
         call missing_group(deck, 'model', error); return
      end if
      msg0 = ''
      read (grp%lines, nml=model, iostat=ios, iomsg=msg0)
      if (ios /= 0) then
         do i = 1, size(grp%items)
            call group_item(grp, i, rec); msg = ''
            read (rec, nml=model, iostat=ios, iomsg=msg)
            if (ios /= 0) exit
         end do
         if (ios == 0) msg = msg0
         call group_read_error(deck, grp, i, msg, error); return
      end if
      call need_int(deck, 'model', 'n_dof', n_dof, 1, max_dof, error)
      if (allocated(error)) return
      n = n_dof
      call need_reals(deck, 'model', 'mass', mass, n, 'kg', error, positive=.true.)
      if (allocated(error)) return
      call optional_reals(deck, 'model', 'u0', u0, n, default_u0, 'm', error)
      if (allocated(error)) return
      call optional_reals(deck, 'model', 'v0', v0, n, default_v0, 'm/s', error)
      if (allocated(error)) return
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
      character(len=512) :: msg, msg0
      character(len=:), allocatable :: rec
      integer :: ios, i, n
      logical :: found

      n_springs = unset_int
      allocate (node_i(max_springs), node_j(max_springs), k(max_springs))
      node_i = unset_int; node_j = unset_int; k = unset
      call find_group(deck, 'springs', grp, found, error)
      if (allocated(error)) return
      if (.not. found) then
         call missing_group(deck, 'springs', error); return
      end if
      msg0 = ''
      read (grp%lines, nml=springs, iostat=ios, iomsg=msg0)
      if (ios /= 0) then
         do i = 1, size(grp%items)
            call group_item(grp, i, rec); msg = ''
            read (rec, nml=springs, iostat=ios, iomsg=msg)
            if (ios /= 0) exit
         end do
         if (ios == 0) msg = msg0
         call group_read_error(deck, grp, i, msg, error); return
      end if
      call need_int(deck, 'springs', 'n_springs', n_springs, 0, max_springs, error)
      if (allocated(error)) return
      n = n_springs
      call node_list(deck, 'springs', 'node_i', node_i, n, 1, cfg%model%n_dof, error)
      if (allocated(error)) return
      call node_list(deck, 'springs', 'node_j', node_j, n, 0, cfg%model%n_dof, error)
      if (allocated(error)) return
      call need_reals(deck, 'springs', 'k', k, n, 'N/m', error, positive=.true.)
      if (allocated(error)) return
      do i = 1, n
         if (node_i(i) == node_j(i)) then
            call bad(deck, 'springs', 'node_j('//trim(fmt_int(i))//')', trim(fmt_int(node_j(i))), &
                     'different from node_i('//trim(fmt_int(i))//') = '// &
                     trim(fmt_int(node_i(i)))//': a spring joins two different nodes', error)
            return
         end if
      end do
      cfg%model%n_springs = n
      cfg%model%spring_i = node_i(1:n)
      cfg%model%spring_j = node_j(1:n)
      cfg%model%spring_k = k(1:n)
   end subroutine read_springs_group

   ! ---------------------------------------------------------------- &damping
   subroutine read_damping_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      character(len=name_len) :: damping_type
      real(dp) :: xi, period, rayleigh_a0, rayleigh_a1
      namelist /damping/ damping_type, xi, period, rayleigh_a0, rayleigh_a1
      type(group_text) :: grp
      character(len=512) :: msg, msg0
      character(len=:), allocatable :: rec, choices
      integer :: ios, i
      logical :: found

      damping_type = ''
      xi = default_xi; period = default_period
      rayleigh_a0 = default_rayleigh_a0; rayleigh_a1 = default_rayleigh_a1
      call find_group(deck, 'damping', grp, found, error)
      if (allocated(error)) return
      if (.not. found) then
         call missing_group(deck, 'damping', error); return
      end if
      call check_length(deck, grp, 'damping_type', name_len, error)
      if (allocated(error)) return
      msg0 = ''
      read (grp%lines, nml=damping, iostat=ios, iomsg=msg0)
      if (ios /= 0) then
         do i = 1, size(grp%items)
            call group_item(grp, i, rec); msg = ''
            read (rec, nml=damping, iostat=ios, iomsg=msg)
            if (ios /= 0) exit
         end do
         if (ios == 0) msg = msg0
         call group_read_error(deck, grp, i, msg, error); return
      end if
      cfg%model%damping = keyword_id(damping_types, damping_type)
      select case (cfg%model%damping)
      case (damping_stiffness)
         call check_real(deck, 'damping', 'xi', xi, 0.0_dp, 1.0_dp, '', error, open_hi=.true.)
         if (allocated(error)) return
         call check_real(deck, 'damping', 'period', period, 0.0_dp, max_magnitude, 's', error)
         if (allocated(error)) return
      case (damping_rayleigh)
         call check_real(deck, 'damping', 'rayleigh_a0', rayleigh_a0, 0.0_dp, max_magnitude, '1/s', error)
         if (allocated(error)) return
         call check_real(deck, 'damping', 'rayleigh_a1', rayleigh_a1, 0.0_dp, max_magnitude, 's', error)
         if (allocated(error)) return
      case (damping_none)
      case default
         call keyword_choices(damping_types, choices)
         call bad(deck, 'damping', 'damping_type', "'"//trim(damping_type)//"'", 'one of '//choices, error)
         return
      end select
      cfg%model%xi = xi
      cfg%model%period = period
      cfg%model%rayleigh_a0 = rayleigh_a0
      cfg%model%rayleigh_a1 = rayleigh_a1
   end subroutine read_damping_group

   ! ---------------------------------------------------------------- &friction
   subroutine read_friction_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      integer :: n_devices
      integer, allocatable :: node_i(:), node_j(:)
      character(len=name_len), allocatable :: law(:)
      real(dp), allocatable :: p(:), mu(:), eps(:), eps1(:), f(:)
      namelist /friction/ n_devices, node_i, node_j, law, p, mu, eps, eps1, f
      type(group_text) :: grp
      character(len=512) :: msg, msg0
      character(len=:), allocatable :: rec, idx, choices
      integer :: ios, i, n, id
      logical :: found

      n_devices = default_n_devices
      allocate (node_i(max_devices), node_j(max_devices), law(max_devices), p(max_devices), &
                mu(max_devices), eps(max_devices), eps1(max_devices), f(max_devices))
      node_i = unset_int; node_j = unset_int; law = ''
      p = unset; mu = unset; eps = unset; eps1 = unset; f = unset
      call find_group(deck, 'friction', grp, found, error)
      if (allocated(error)) return
      cfg%model%n_devices = 0
      allocate (cfg%model%dev(0))
      if (.not. found) return
      call check_length(deck, grp, 'law', name_len, error)
      if (allocated(error)) return
      msg0 = ''
      read (grp%lines, nml=friction, iostat=ios, iomsg=msg0)
      if (ios /= 0) then
         do i = 1, size(grp%items)
            call group_item(grp, i, rec); msg = ''
            read (rec, nml=friction, iostat=ios, iomsg=msg)
            if (ios /= 0) exit
         end do
         if (ios == 0) msg = msg0
         call group_read_error(deck, grp, i, msg, error); return
      end if
      call need_int(deck, 'friction', 'n_devices', n_devices, 0, max_devices, error)
      if (allocated(error)) return
      n = n_devices
      call node_list(deck, 'friction', 'node_i', node_i, n, 1, cfg%model%n_dof, error)
      if (allocated(error)) return
      call node_list(deck, 'friction', 'node_j', node_j, n, 0, cfg%model%n_dof, error)
      if (allocated(error)) return
      call need_reals(deck, 'friction', 'p', p, n, 'N', error, positive=.false.)
      if (allocated(error)) return
      call need_reals(deck, 'friction', 'mu', mu, n, '', error, positive=.false.)
      if (allocated(error)) return
      call optional_reals(deck, 'friction', 'eps', eps, n, default_eps, 'm/s', error, positive=.true.)
      if (allocated(error)) return
      call optional_reals(deck, 'friction', 'eps1', eps1, n, default_eps1, 'm/s', error, positive=.true.)
      if (allocated(error)) return
      call optional_reals(deck, 'friction', 'f', f, n, default_f, 'm', error, positive=.true.)
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
         if (node_i(i) == node_j(i)) then
            call bad(deck, 'friction', 'node_j'//idx, trim(fmt_int(node_j(i))), 'different from node_i'//idx//' = '// &
                     trim(fmt_int(node_i(i)))//': a device joins two different nodes', error)
            return
         end if
         if (p(i)*mu(i) /= 0.0_dp .and. p(i)*mu(i) < min_scale) then
            call bad(deck, 'friction', 'p'//idx//' * mu'//idx, trim(fmt_real(p(i)*mu(i))), '0 (no friction) or at '// &
                     'least '//trim(fmt_real(min_scale))//' N: the friction force P mu of a device (here P = '// &
                     trim(fmt_real(p(i)))//' N, mu = '//trim(fmt_real(mu(i)))//')', error)
            return
         end if
         id = law_id(law(i))
         if (id == 0) then
            call law_choices(choices)
            if (len_trim(law(i)) == 0) then
               call bad(deck, 'friction', 'law'//idx, '(not given)', 'one of '//choices, error)
            else
               call bad(deck, 'friction', 'law'//idx, "'"//trim(law(i))//"'", 'one of '//choices, error)
            end if
            return
         end if
         cfg%model%dev(i) = device_type(node_i=node_i(i), node_j=node_j(i), law=id, &
                                        p=p(i), mu=mu(i), eps=eps(i), eps1=eps1(i), f=f(i))
      end do
      cfg%model%n_devices = n
   end subroutine read_friction_group

   ! ---------------------------------------------------------------- &excitation
   subroutine read_excitation_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      character(len=name_len) :: excitation_type, record_kind, record_format, record_units
      integer :: kind_id
      character(len=path_len) :: record_file
      real(dp) :: amplitude, frequency, duration, dt_record, record_scale, factor
      integer :: ramp_cycles
      logical :: known
      namelist /excitation/ excitation_type, amplitude, frequency, ramp_cycles, duration, dt_record, &
         record_file, record_kind, record_scale, record_format, record_units
      type(group_text) :: grp
      character(len=512) :: msg, msg0
      character(len=:), allocatable :: rec, path, choices
      integer :: ios, i
      logical :: found

      excitation_type = ''; record_kind = record_kinds(default_record_kind)%name; record_file = ''
      amplitude = unset; frequency = unset; duration = unset; dt_record = unset
      record_scale = default_record_scale
      ramp_cycles = default_ramp_cycles
      record_format = 'auto'; record_units = ''
      call find_group(deck, 'excitation', grp, found, error)
      if (allocated(error)) return
      if (.not. found) then
         call missing_group(deck, 'excitation', error); return
      end if
      call check_length(deck, grp, 'excitation_type', name_len, error)
      if (.not. allocated(error)) call check_length(deck, grp, 'record_kind', name_len, error)
      if (.not. allocated(error)) call check_length(deck, grp, 'record_format', name_len, error)
      if (.not. allocated(error)) call check_length(deck, grp, 'record_units', name_len, error)
      if (.not. allocated(error)) call check_length(deck, grp, 'record_file', path_len, error)
      if (allocated(error)) return
      msg0 = ''
      read (grp%lines, nml=excitation, iostat=ios, iomsg=msg0)
      if (ios /= 0) then
         do i = 1, size(grp%items)
            call group_item(grp, i, rec); msg = ''
            read (rec, nml=excitation, iostat=ios, iomsg=msg)
            if (ios /= 0) exit
         end do
         if (ios == 0) msg = msg0
         call group_read_error(deck, grp, i, msg, error); return
      end if
      ! a record whose file gives DT (AT2) may leave dt_record out
      if (.not. (keyword_id(excitation_types, excitation_type) == excitation_record .and. dt_record == unset)) then
         call need_real(deck, 'excitation', 'dt_record', dt_record, 's', error)
         if (allocated(error)) return
      end if
      cfg%exc%dt_record = dt_record
      cfg%exc%kind = keyword_id(excitation_types, excitation_type)
      select case (cfg%exc%kind)
      case (excitation_harmonic)
         call need_real(deck, 'excitation', 'amplitude', amplitude, 'm', error, positive=.false.)
         if (allocated(error)) return
         call need_real(deck, 'excitation', 'frequency', frequency, 'Hz', error)
         if (allocated(error)) return
         if (ramp_cycles < 0) then
            call bad(deck, 'excitation', 'ramp_cycles', trim(fmt_int(ramp_cycles)), '>= 0', error); return
         end if
         call need_real(deck, 'excitation', 'duration', duration, 's', error)
         if (allocated(error)) return
         cfg%exc%amplitude = amplitude
         cfg%exc%frequency = frequency
         cfg%exc%ramp_cycles = ramp_cycles
      case (excitation_record)
         if (len_trim(record_file) == 0) then
            call bad(deck, 'excitation', 'record_file', "''", 'the path of the record file', error); return
         end if
         if (.not. ieee_is_finite(record_scale) .or. record_scale == 0.0_dp) then
            call bad(deck, 'excitation', 'record_scale', trim(fmt_real(record_scale)), 'finite and non-zero', error)
            return
         end if
         call check_magnitude(deck, 'excitation', 'record_scale', record_scale, '', .true., error)
         if (allocated(error)) return
         kind_id = keyword_id(record_kinds, record_kind)
         if (kind_id == 0) then
            call keyword_choices(record_kinds, choices)
            call bad(deck, 'excitation', 'record_kind', "'"//trim(record_kind)//"'", 'one of '//choices, error)
            return
         end if
         select case (lower(trim(record_format)))
         case ('auto', 'at2', 'values', 'time_value')
         case default
            call bad(deck, 'excitation', 'record_format', "'"//trim(record_format)//"'", 'one of '//record_formats, error)
            return
         end select
         if (len_trim(record_units) > 0) then
            call units_factor(lower(trim(record_units)), kind_id == record_displacement, factor, known)
            if (.not. known) then
               call bad(deck, 'excitation', 'record_units', "'"//trim(record_units)//"'", 'one of '// &
                        record_units_list//", matching record_kind = '"//trim(record_kind)//"'", error)
               return
            end if
         end if
         call relative_to(deck%path, trim(record_file), path)
         call read_record(path, trim(record_format), kind_id == record_displacement, &
                          trim(record_units), record_scale, merge(dt_record, 0.0_dp, dt_record /= unset), &
                          cfg%exc%acc, cfg%record, error)
         if (allocated(error)) then
            error%message = deck%path//", group &excitation, record_file = '"//trim(record_file)//"': "// &
                            error%message
            return
         end if
         cfg%record%path = trim(record_file)   ! as the deck gives it (like the summary's "deck")
         dt_record = cfg%record%dt
         cfg%exc%dt_record = dt_record
         call check_magnitude(deck, 'excitation', "dt_record (the record file's DT)", dt_record, 's', .true., error)
         if (allocated(error)) return
         if (.not. (cfg%record%peak_acc <= max_magnitude)) then
            call bad(deck, 'excitation', 'record_file', "'"//trim(record_file)//"'", 'a record whose table '// &
                     'acceleration (after record_units and record_scale = '//trim(fmt_real(record_scale))// &
                     ') stays within '//trim(fmt_real(max_magnitude))//' m/s2 in magnitude; it reaches '// &
                     trim(fmt_real(cfg%record%peak_acc))//' m/s2', error)
            return
         end if
         if (duration == unset) duration = (size(cfg%exc%acc) - 1)*dt_record
         call need_real(deck, 'excitation', 'duration', duration, 's', error)
         if (allocated(error)) return
      case (excitation_none)
         call need_real(deck, 'excitation', 'duration', duration, 's', error)
         if (allocated(error)) return
      case default
         call keyword_choices(excitation_types, choices)
         call bad(deck, 'excitation', 'excitation_type', "'"//trim(excitation_type)//"'", 'one of '//choices, error)
         return
      end select
      cfg%exc%duration = duration
   end subroutine read_excitation_group

   ! ---------------------------------------------------------------- &integration
   subroutine read_integration_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      character(len=name_len) :: technique
      real(dp) :: beta, gamma, n, dt_min, theta
      integer :: n1, n2
      logical :: check_correctness
      namelist /integration/ technique, beta, gamma, n1, n2, n, check_correctness, dt_min, theta
      type(group_text) :: grp
      character(len=512) :: msg, msg0
      character(len=:), allocatable :: rec, choices
      integer :: ios, i, technique_id
      logical :: found

      technique = technique_name(default_technique)
      beta = default_beta; gamma = default_gamma; n1 = default_n1; n2 = default_n2; n = default_n
      check_correctness = default_check_correctness; dt_min = default_dt_min; theta = default_theta
      call find_group(deck, 'integration', grp, found, error)
      if (allocated(error)) return
      if (found) then
         call check_length(deck, grp, 'technique', name_len, error)
         if (allocated(error)) return
         msg0 = ''
         read (grp%lines, nml=integration, iostat=ios, iomsg=msg0)
         if (ios /= 0) then
            do i = 1, size(grp%items)
               call group_item(grp, i, rec); msg = ''
               read (rec, nml=integration, iostat=ios, iomsg=msg)
               if (ios /= 0) exit
            end do
            if (ios == 0) msg = msg0
            call group_read_error(deck, grp, i, msg, error); return
         end if
      end if
      technique_id = keyword_id(techniques, technique)
      if (technique_id == 0) then
         call keyword_choices(techniques, choices)
         call bad(deck, 'integration', 'technique', "'"//trim(technique)//"'", 'one of '//choices, error)
         return
      end if
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
      ! the run takes duration / dt1 steps, counted in a default integer
      if (cfg%exc%duration/(cfg%exc%dt_record/n1) > 2.0e9_dp) then
         call bad(deck, 'integration', 'n1', trim(fmt_int(n1)), 'such that duration / (dt_record / n1) = '// &
                  trim(fmt_real(cfg%exc%duration/(cfg%exc%dt_record/n1)))//' steps stays below 2e9 (duration = '// &
                  trim(fmt_real(cfg%exc%duration))//' s)', error)
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
   end subroutine read_integration_group

   ! ---------------------------------------------------------------- &output
   subroutine read_output_group(deck, cfg, error)
      type(deck_text), intent(in) :: deck
      type(run_config), intent(inout) :: cfg
      type(error_type), allocatable, intent(out) :: error
      character(len=path_len) :: dir, name
      integer :: output_every
      logical :: write_history
      namelist /output/ dir, name, output_every, write_history
      type(group_text) :: grp
      character(len=512) :: msg, msg0
      character(len=:), allocatable :: rec
      integer :: ios, i
      logical :: found

      dir = default_dir; output_every = default_output_every; write_history = default_write_history
      call stem(deck%path, name)
      call find_group(deck, 'output', grp, found, error)
      if (allocated(error)) return
      if (found) then
         call check_length(deck, grp, 'dir', path_len, error)
         if (.not. allocated(error)) call check_length(deck, grp, 'name', path_len, error)
         if (allocated(error)) return
         msg0 = ''
         read (grp%lines, nml=output, iostat=ios, iomsg=msg0)
         if (ios /= 0) then
            do i = 1, size(grp%items)
               call group_item(grp, i, rec); msg = ''
               read (rec, nml=output, iostat=ios, iomsg=msg)
               if (ios /= 0) exit
            end do
            if (ios == 0) msg = msg0
            call group_read_error(deck, grp, i, msg, error); return
         end if
      end if
      if (len_trim(dir) == 0) then
         call bad(deck, 'output', 'dir', "''", 'a directory path', error); return
      end if
      if (len_trim(name) == 0 .or. index(trim(name), '/') > 0) then
         call bad(deck, 'output', 'name', "'"//trim(name)//"'", 'a file name without directory', error); return
      end if
      if (output_every < 0) then
         call bad(deck, 'output', 'output_every', trim(fmt_int(output_every)), '>= 0 (0 = at the record step)', error)
         return
      end if
      cfg%out%dir = trim(dir)
      cfg%out%name = trim(name)
      cfg%out%history = write_history
      cfg%opts%output_every = output_every
   end subroutine read_output_group

   ! ---------------------------------------------------------------- helpers
   subroutine missing_group(deck, group, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group
      type(error_type), allocatable, intent(out) :: error
      call fatal_error(error, deck%path//": required group &"//group//" is missing")
   end subroutine missing_group

   subroutine bad(deck, group, var, val, must, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var, val, must
      type(error_type), allocatable, intent(out) :: error
      call fatal_error(error, deck%path//", group &"//group//": "//var//" = "//val//" is invalid: must be "//must)
   end subroutine bad

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

   subroutine need_int(deck, group, var, x, lo, hi, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var
      integer, intent(in) :: x, lo, hi
      type(error_type), allocatable, intent(out) :: error
      if (x == unset_int) then
         call fatal_error(error, deck%path//", group &"//group//": "//var//" is not given"); return
      end if
      if (x < lo .or. x > hi) call bad(deck, group, var, trim(fmt_int(x)), 'in '//trim(fmt_int(lo))//'..'//trim(fmt_int(hi)), error)
   end subroutine need_int

   subroutine need_real(deck, group, var, x, unit, error, positive)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var, unit
      real(dp), intent(in) :: x
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: positive
      logical :: pos
      pos = .true.
      if (present(positive)) pos = positive
      if (x == unset) then
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
   subroutine need_reals(deck, group, var, x, n, unit, error, positive)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var, unit
      real(dp), intent(in) :: x(:)
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in) :: positive
      integer :: i
      do i = 1, n
         call need_real(deck, group, var//'('//trim(fmt_int(i))//')', x(i), unit, error, positive)
         if (allocated(error)) return
      end do
      call no_extra(deck, group, var, x, n, error)
   end subroutine need_reals

   !> Values not given take a default; given ones must be finite (and > 0 if positive).
   subroutine optional_reals(deck, group, var, x, n, default, unit, error, positive)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var, unit
      real(dp), intent(inout) :: x(:)
      integer, intent(in) :: n
      real(dp), intent(in) :: default
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: positive
      integer :: i
      logical :: pos
      pos = .false.
      if (present(positive)) pos = positive
      do i = 1, n
         if (x(i) == unset) x(i) = default
         if (.not. ieee_is_finite(x(i))) then
            call bad(deck, group, var//'('//trim(fmt_int(i))//')', trim(fmt_real(x(i))), 'a finite number', error); return
         end if
         if (pos .and. x(i) <= 0.0_dp) then
            call bad(deck, group, var//'('//trim(fmt_int(i))//')', trim(fmt_real(x(i))), '> 0 '//unit, error); return
         end if
         call check_magnitude(deck, group, var//'('//trim(fmt_int(i))//')', x(i), unit, pos, error)
         if (allocated(error)) return
      end do
      call no_extra(deck, group, var, x, n, error)
   end subroutine optional_reals

   subroutine no_extra(deck, group, var, x, n, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var
      real(dp), intent(in) :: x(:)
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      integer :: last
      last = findloc(x /= unset, .true., 1, back=.true.)
      if (last > n) call bad(deck, group, var//'('//trim(fmt_int(last))//')', trim(fmt_real(x(last))), &
                             'absent: only '//trim(fmt_int(n))//' value(s) are expected', error)
   end subroutine no_extra

   subroutine node_list(deck, group, var, x, n, lo, hi, error)
      type(deck_text), intent(in) :: deck
      character(len=*), intent(in) :: group, var
      integer, intent(in) :: x(:), n, lo, hi
      type(error_type), allocatable, intent(out) :: error
      integer :: i, last
      do i = 1, n
         if (x(i) == unset_int) then
            call fatal_error(error, deck%path//", group &"//group//": "//var//'('//trim(fmt_int(i))//") is not given")
            return
         end if
         if (x(i) < lo .or. x(i) > hi) then
            call bad(deck, group, var//'('//trim(fmt_int(i))//')', trim(fmt_int(x(i))), 'a node in '//trim(fmt_int(lo))//'..'// &
                     trim(fmt_int(hi))//merge(' (0 = table)', '            ', lo == 0), error)
            return
         end if
      end do
      last = findloc(x /= unset_int, .true., 1, back=.true.)
      if (last > n) call bad(deck, group, var//'('//trim(fmt_int(last))//')', trim(fmt_int(x(last))), &
                             'absent: only '//trim(fmt_int(n))//' value(s) are expected', error)
   end subroutine node_list

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
