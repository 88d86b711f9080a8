!> Names and defaults of the deck's settings, in one place: the keyword tables (friction
!> laws, techniques, damping types, excitation types, record kinds), from which the deck
!> reader looks names up and builds its messages, and the default of every optional
!> namelist variable, which the reader and the model's types start from.
!> docs/namelist.md documents each of them.
!>
!> The id of a keyword is its position in its table. Adding a friction law is one row in
!> `laws` with its id below it (public), one module in fortran/friction and one case in each
!> `select case` of fd_friction.
module fd_names
   use fd_kinds, only: dp
   use fd_textio, only: lower
   implicit none
   private

   public :: keyword_type, law_type, keyword_len
   public :: laws, law_velocity, law_hysteretic, law_coulomb
   public :: techniques, technique_newmark, technique_event_driven, technique_moreau_jean
   public :: technique_traits_type, technique_traits, technique_step_rule, technique_integrates
   public :: rule_none, rule_newmark, rule_theta
   public :: damping_types, damping_stiffness, damping_rayleigh, damping_none, damping_modal
   public :: default_modal_modes, max_default_modal_modes
   public :: excitation_types, excitation_harmonic, excitation_record, excitation_none
   public :: record_kinds, record_acceleration, record_displacement
   public :: linear_systems, linear_system_auto, linear_system_dense, linear_system_banded, linear_system_sparse
   public :: refinements, refinement_step, refinement_nested, refinement_implicit
   public :: mu_laws, mu_constant, mu_exponential, mu_table
   public :: mode_systems, system_stuck, system_free
   public :: keyword_id, keyword_name, keyword_choices, law_id, law_choices, law_name, technique_name
   public :: default_u0, default_v0, default_xi, default_period, default_rayleigh_a0, default_rayleigh_a1
   public :: default_n_devices, default_eps, default_eps1, default_f
   public :: default_ramp_cycles, default_record_kind, default_record_scale
   public :: default_technique, default_beta, default_gamma, default_n1, default_n2, default_n
   public :: default_check_correctness, default_dt_min, default_theta, default_linear_system
   public :: default_refinement
   public :: default_dir, default_output_every, default_write_history, default_max_history_mb
   public :: default_mu_law, default_mode_system, default_n_modes, default_radius, default_storey_height
   public :: label_len, max_mu_points

   integer, parameter :: keyword_len = 16   !! length of a keyword in the tables
   integer, parameter :: label_len = 32     !! length of a label (a DOF's, a device's, a storey's)
   integer, parameter :: max_mu_points = 32 !! points of a table mu(v)

   !> A keyword of the deck and what it means (shown in messages when not empty).
   type :: keyword_type
      character(len=keyword_len) :: name = ''  !! the keyword, lower case
      character(len=40) :: note = ''           !! its meaning, for messages
   end type keyword_type

   !> A friction law: its keyword, and whether its force is a function of the device's
   !> state (regularized: integrated step by step by Newmark) or set-valued (exact Coulomb:
   !> the force of a sticking device is whatever keeps it stuck, found event by event).
   type, extends(keyword_type) :: law_type
      logical :: regularized = .true.          !! a force law Newmark can integrate
   end type law_type

   ! ------------------------------------------------------------------ friction laws
   type(law_type), parameter :: laws(*) = [ &
                                law_type('velocity', '', .true.), &     ! law_velocity, eqs. 6-11
                                law_type('hysteretic', '', .true.), &   ! law_hysteretic, eqs. 2-5
                                law_type('coulomb', '', .false.)]       ! law_coulomb, exact
   integer, parameter :: law_velocity = 1   !! velocity model, eqs. 6-11
   integer, parameter :: law_hysteretic = 2 !! hysteretic model, eqs. 2-5
   integer, parameter :: law_coulomb = 3    !! exact (set-valued) Coulomb friction

   ! ------------------------------------------------------------------ techniques
   type(keyword_type), parameter :: techniques(*) = [ &
                                    keyword_type('newmark', 'regularized laws'), &
                                    keyword_type('event_driven', "exact, law 'coulomb'"), &
                                    keyword_type('moreau_jean', "time stepping, law 'coulomb'")]
   integer, parameter :: technique_newmark = 1      !! Newmark with the paper's step control
   integer, parameter :: technique_event_driven = 2 !! exact event-driven Coulomb technique
   integer, parameter :: technique_moreau_jean = 3  !! Moreau-Jean time stepping, exact Coulomb impulses

   ! the rule of a technique's steps dt1, which the step checks (fd_*_resolution) analyse
   integer, parameter :: rule_none = 0      !! no step dt1 (event by event)
   integer, parameter :: rule_newmark = 1   !! Newmark's beta, gamma
   integer, parameter :: rule_theta = 2     !! the theta-method (Moreau-Jean)

   !> What a technique says of itself, whatever the deck's settings: the laws it integrates,
   !> the rule of its steps, whether it refines a step, what its history rows hold. The
   !> technique's answer to technique_traits (one row of technique_table, by id): a constant
   !> of the names table, so that every layer may ask it (the result's history shape is
   !> sized before any technique runs). docs/architecture.md, "Where to add".
   type :: technique_traits_type
      logical :: regularized_laws = .false.  !! integrates the regularized laws (laws%regularized)
      logical :: set_valued_laws = .false.   !! integrates the set-valued law (exact Coulomb)
      integer :: step_rule = rule_none       !! the rule of its steps dt1 (rule_*)
      logical :: refines_steps = .false.     !! refines a step dt1 (dt2, dt_min: fd_step_limits)
      logical :: envelope = .false.          !! its history rows carry the maxima since the last row
   end type technique_traits_type

   !> Each technique's traits, by id (the order of `techniques`).
   type(technique_traits_type), parameter :: technique_table(*) = [ &
      technique_traits_type(regularized_laws=.true., step_rule=rule_newmark, refines_steps=.true.), & ! newmark
      technique_traits_type(set_valued_laws=.true., envelope=.true.), &                               ! event_driven
      technique_traits_type(set_valued_laws=.true., step_rule=rule_theta)]                            ! moreau_jean

   ! ------------------------------------------------------------------ damping types
   type(keyword_type), parameter :: damping_types(*) = [ &
                                    keyword_type('stiffness', 'C = psi K, the paper'), &
                                    keyword_type('rayleigh', 'C = a0 M + a1 K'), &
                                    keyword_type('none', ''), &
                                    keyword_type('modal', 'xi per mode of the stuck system')]
   integer, parameter :: damping_stiffness = 1 !! C = psi K, psi = T xi / pi (the paper)
   integer, parameter :: damping_rayleigh = 2  !! C = a0 M + a1 K
   integer, parameter :: damping_none = 3      !! no viscous damping
   integer, parameter :: damping_modal = 4     !! C = M Phi diag(2 xi w / m) Phi' M over the kept modes

   ! ------------------------------------------------------------------ excitation types
   type(keyword_type), parameter :: excitation_types(*) = [ &
                                    keyword_type('harmonic', ''), &
                                    keyword_type('record', ''), &
                                    keyword_type('none', '')]
   integer, parameter :: excitation_harmonic = 1 !! x0 = a0 R(t) sin(2 pi f t)
   integer, parameter :: excitation_record = 2   !! recorded acceleration samples
   integer, parameter :: excitation_none = 3     !! table at rest (free vibration)

   ! ------------------------------------------------------------------ record kinds
   type(keyword_type), parameter :: record_kinds(*) = [ &
                                    keyword_type('acceleration', 'm/s2 after record_scale'), &
                                    keyword_type('displacement', 'm')]
   integer, parameter :: record_acceleration = 1 !! the record holds table accelerations
   integer, parameter :: record_displacement = 2 !! the record holds table displacements

   ! ------------------------------------------------------------------ linear systems
   type(keyword_type), parameter :: linear_systems(*) = [ &
                                    keyword_type('auto', 'dense up to 8 DOFs, sparse where cheaper, else banded'), &
                                    keyword_type('dense', ''), &
                                    keyword_type('banded', ''), &
                                    keyword_type('sparse', 'CHOLMOD')]
   integer, parameter :: linear_system_auto = 1   !! storage chosen by the kernel (fd_banded)
   integer, parameter :: linear_system_dense = 2  !! dense effective stiffness
   integer, parameter :: linear_system_banded = 3 !! banded, reverse Cuthill-McKee ordering
   integer, parameter :: linear_system_sparse = 4 !! sparse, CHOLMOD (fd_sparse)
   ! ------------------------------------------------------------------ step refinement (Newmark)
   type(keyword_type), parameter :: refinements(*) = [ &
                                    keyword_type('step', 'the paper: whole dt1 step in dt2 steps'), &
                                    keyword_type('nested', 'split by the factors of n2'), &
                                    keyword_type('implicit', 'the dt1 step in the phases it ends in')]
   integer, parameter :: refinement_step = 1   !! a refined dt1 step is redone as n2 steps dt2
   integer, parameter :: refinement_nested = 2 !! split level by level, only the pieces that change
   integer, parameter :: refinement_implicit = 3 !! the dt1 step redone in the phases it ends in
   ! ------------------------------------------------------------------ mu(v), velocity law
   type(keyword_type), parameter :: mu_laws(*) = [ &
                                    keyword_type('constant', 'mu'), &
                                    keyword_type('exponential', 'mu_max, mu_min, mu_rate'), &
                                    keyword_type('table', 'mu_table_v, mu_table_mu')]
   integer, parameter :: mu_constant = 1    !! mu independent of the sliding velocity
   integer, parameter :: mu_exponential = 2 !! mu = mu_max - (mu_max - mu_min) exp(-rate |v|)
   integer, parameter :: mu_table = 3       !! mu linear between (v, mu) points

   ! ------------------------------------------------------------------ systems of the modes
   type(keyword_type), parameter :: mode_systems(*) = [ &
                                    keyword_type('stuck', 'every device stuck'), &
                                    keyword_type('free', 'every device free')]
   integer, parameter :: system_stuck = 1   !! every device in its sticking phase
   integer, parameter :: system_free = 2    !! every device removed (no friction)

   ! ------------------------------------------------------------------ defaults
   ! &model
   real(dp), parameter :: default_u0 = 0.0_dp            !! initial displacement [m]
   real(dp), parameter :: default_v0 = 0.0_dp            !! initial velocity [m/s]
   ! &damping
   real(dp), parameter :: default_xi = 0.0_dp            !! damping ratio [-]
   real(dp), parameter :: default_period = 0.0_dp        !! stuck period, 0 = computed [s]
   real(dp), parameter :: default_rayleigh_a0 = 0.0_dp   !! [1/s]
   real(dp), parameter :: default_rayleigh_a1 = 0.0_dp   !! [s]
   ! &friction
   integer, parameter :: default_n_devices = 0           !! no devices
   real(dp), parameter :: default_eps = 1.0e-3_dp        !! velocity band eps [m/s]
   real(dp), parameter :: default_eps1 = 1.0e-3_dp       !! end of sliding eps1 [m/s]
   real(dp), parameter :: default_f = 1.0e-5_dp          !! sticking displacement f [m]
   integer, parameter :: default_mu_law = mu_constant    !! mu(v) of the velocity law
   real(dp), parameter :: default_radius = 0.0_dp        !! isolator radius, 0 = flat [m]
   ! &damping ('rayleigh' from xi at two modes)
   integer, parameter :: default_mode_system = system_stuck
   ! &damping ('modal')
   integer, parameter :: default_modal_modes = 0         !! 0 = every mode of the stuck system, at most:
   integer, parameter :: max_default_modal_modes = 20    !! the modes 'modal' damping keeps by default
   ! &storeys
   real(dp), parameter :: default_storey_height = 0.0_dp !! 0 = not given [m]
   ! &excitation
   integer, parameter :: default_ramp_cycles = 0         !! no ramp
   integer, parameter :: default_record_kind = record_acceleration
   real(dp), parameter :: default_record_scale = 1.0_dp  !! [-]
   ! &integration
   integer, parameter :: default_technique = technique_newmark
   real(dp), parameter :: default_beta = 0.25_dp         !! Newmark beta
   real(dp), parameter :: default_gamma = 0.5_dp         !! Newmark gamma
   integer, parameter :: default_n1 = 20                 !! dt1 = dt_record / n1
   integer, parameter :: default_n2 = 50                 !! dt2 = dt1 / n2
   real(dp), parameter :: default_n = 10.0_dp            !! n of eqs. 9 and 12
   logical, parameter :: default_check_correctness = .true.
   real(dp), parameter :: default_dt_min = 0.0_dp        !! 0 = dt2 / 2**10 [s]
   real(dp), parameter :: default_theta = 0.5_dp         !! theta of the Moreau-Jean technique
   integer, parameter :: default_linear_system = linear_system_auto
   integer, parameter :: default_refinement = refinement_step
   ! &output
   character(len=*), parameter :: default_dir = 'out'    !! output directory
   integer, parameter :: default_output_every = 0        !! 0 = every dt_record
   logical, parameter :: default_write_history = .true.
   integer, parameter :: default_max_history_mb = 2048   !! largest history file a run writes [MiB]
   integer, parameter :: default_n_modes = 10            !! modes reported per system

contains

   !> Id (position in the table) of a keyword, compared without case and trailing blanks;
   !> 0 when the table does not hold it.
   pure integer function keyword_id(table, word) result(id)
      type(keyword_type), intent(in) :: table(:)  !! the keyword table
      character(len=*), intent(in) :: word        !! the word of the deck

      do id = 1, size(table)
         if (table(id)%name == lower(trim(word))) return
      end do
      id = 0
   end function keyword_id

   !> The keyword of an id in its table ('unknown' for an id not in it), left-adjusted.
   pure function keyword_name(table, id) result(name)
      type(keyword_type), intent(in) :: table(:)  !! the keyword table
      integer, intent(in) :: id                   !! the id (position in the table)
      character(len=keyword_len) :: name          !! its keyword

      name = 'unknown'
      if (id >= 1 .and. id <= size(table)) name = table(id)%name
   end function keyword_name

   !> Id of a friction law from its name; 0 for an unknown name.
   pure integer function law_id(word) result(id)
      character(len=*), intent(in) :: word  !! the word of the deck

      ! over the table itself: laws%keyword_type, a section of a constant, is copied to a
      ! temporary at every call
      do id = 1, size(laws)
         if (laws(id)%keyword_type%name == lower(trim(word))) return
      end do
      id = 0
   end function law_id

   !> The keywords of a table for a message: 'a' (note), 'b', 'c'.
   pure subroutine keyword_choices(table, text)
      type(keyword_type), intent(in) :: table(:)        !! the keyword table
      character(len=:), allocatable, intent(out) :: text !! the list
      integer :: i

      text = ''
      do i = 1, size(table)
         if (i > 1) text = text//', '
         text = text//"'"//trim(table(i)%name)//"'"
         if (len_trim(table(i)%note) > 0) text = text//' ('//trim(table(i)%note)//')'
      end do
   end subroutine keyword_choices

   !> The names of the laws for a message: 'a', 'b', 'c' (with regularized: only the laws
   !> that are, or are not, regularized).
   pure subroutine law_choices(text, regularized)
      character(len=:), allocatable, intent(out) :: text !! the list
      logical, intent(in), optional :: regularized       !! which laws to list (default all)
      type(keyword_type) :: table(size(laws))
      integer :: i, n

      n = 0
      do i = 1, size(laws)
         if (present(regularized)) then
            if (laws(i)%regularized .neqv. regularized) cycle
         end if
         n = n + 1
         table(n) = laws(i)%keyword_type
      end do
      call keyword_choices(table(1:n), text)
   end subroutine law_choices

   !> Name of a friction law, as written in decks ('unknown' for an id not in the table).
   pure function law_name(law) result(name)
      integer, intent(in) :: law                !! law id
      character(len=keyword_len) :: name        !! its name, left-adjusted

      name = 'unknown'
      if (law >= 1 .and. law <= size(laws)) name = laws(law)%name
   end function law_name

   !> The traits of a technique (the default record, nothing integrated and no step, for an
   !> id not in the table).
   pure function technique_traits(technique) result(traits)
      integer, intent(in) :: technique          !! technique id
      type(technique_traits_type) :: traits     !! what it says of itself

      traits = technique_traits_type()
      if (technique >= 1 .and. technique <= size(technique_table)) traits = technique_table(technique)
   end function technique_traits

   !> The rule of a technique's steps dt1 (rule_none for a technique that takes none).
   pure integer function technique_step_rule(technique) result(rule)
      integer, intent(in) :: technique          !! technique id
      type(technique_traits_type) :: traits

      traits = technique_traits(technique)
      rule = traits%step_rule
   end function technique_step_rule

   !> Whether a technique integrates a law: the regularized laws, or the set-valued one
   !> (laws%regularized); .false. for an id not in either table.
   pure logical function technique_integrates(technique, law) result(integrates)
      integer, intent(in) :: technique          !! technique id
      integer, intent(in) :: law                !! law id
      type(technique_traits_type) :: traits

      integrates = .false.
      if (law < 1 .or. law > size(laws)) return
      traits = technique_traits(technique)
      if (laws(law)%regularized) then
         integrates = traits%regularized_laws
      else
         integrates = traits%set_valued_laws
      end if
   end function technique_integrates

   !> Name of a technique, as written in decks ('unknown' for an id not in the table).
   pure function technique_name(technique) result(name)
      integer, intent(in) :: technique          !! technique id
      character(len=keyword_len) :: name        !! its name, left-adjusted

      name = keyword_name(techniques, technique)
   end function technique_name

end module fd_names
