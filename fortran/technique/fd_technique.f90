!> The one dispatch over the time-integration techniques (`technique` of &integration):
!> 'newmark' (regularized friction laws, the paper's step control), 'event_driven'
!> (exact Coulomb friction, event by event) and 'moreau_jean' (Coulomb friction by
!> nonsmooth time stepping, at building scale). Each technique says what it cannot integrate
!> (a law, a table motion) with an error naming the group, the variable, the value and what
!> to set (check_technique, which the session asks after reading a deck), and what it is:
!> its traits (technique_traits: the laws it integrates, the rule of its steps, whether it
!> refines them, what its history rows hold), which code outside technique/ asks instead of
!> the technique's id. The traits are constants of fd_names' technique table, so that the
!> result layer, below this one, can ask them too. Adding a technique is its module, its rows
!> in fd_names' technique tables (name and traits) and one case in each routine here.
module fd_technique
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int
   use fd_names, only: technique_newmark, technique_event_driven, technique_moreau_jean, techniques, &
                       keyword_choices, technique_name, law_name, technique_traits_type, technique_traits, &
                       technique_integrates, technique_step_rule, linear_system_sparse
   use fd_model, only: model_type, integration_type, source_brace, source_floor_brace, damping_modal
   use fd_step_limits, only: check_step_limits
   use fd_excitation, only: excitation_type, excitation_none
   use fd_result, only: result_type
   use fd_run_control, only: run_control
   use fd_newmark, only: run_newmark, newmark_check
   use fd_event_driven, only: run_event_driven, event_driven_check
   use fd_moreau_jean, only: run_moreau_jean, moreau_jean_check
   use fd_mode_resolution, only: mode_resolution
   use fd_harmonic_resolution, only: harmonic_resolution
   use fd_record_resolution, only: record_resolution
   implicit none
   private

   public :: check_technique, run_technique
   public :: technique_traits_type, technique_traits, technique_integrates, technique_step_rule

contains

   !> An error for anything of the model or the table motion the chosen technique cannot
   !> integrate: a brace (a shorthand of the deck) whose law it does not integrate, what the
   !> technique itself refuses, and for a technique that refines its steps the limits of that
   !> refinement (fd_step_limits). Messages start with "group &...": the session prefixes the
   !> deck.
   subroutine check_technique(model, exc, opts, error)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(integration_type), intent(in) :: opts    !! the technique and its settings
      type(error_type), allocatable, intent(out) :: error !! what cannot be integrated
      type(technique_traits_type) :: traits
      character(len=96) :: fix
      integer :: d

      ! a planar bearing (&bearings) slides on its resultant: Newmark integrates the planar
      ! regularized laws, Moreau-Jean planar Coulomb friction, the event-driven technique none
      do d = 1, model%n_devices
         if (model%dev(d)%partner == 0) cycle
         if (opts%technique == technique_event_driven) then
            call fatal_error(error, "group &integration: technique = '"//trim(technique_name(opts%technique))// &
                             "' does not integrate planar bearings (&bearings, here bearing "// &
                             trim(fmt_int(model%dev(d)%source_index))//"); set technique = 'newmark' or 'moreau_jean'")
            return
         end if
         if (technique_integrates(opts%technique, model%dev(d)%law)) cycle
         if (opts%technique == technique_newmark) then
            fix = "it integrates 'velocity' or 'hysteretic' bearings; set one, or technique = 'moreau_jean'"
         else
            fix = "it integrates 'coulomb' bearings; set law = 'coulomb' or technique = 'newmark'"
         end if
         call fatal_error(error, "group &bearings: law("//trim(fmt_int(model%dev(d)%source_index))//") = '"// &
                          trim(law_name(model%dev(d)%law))//"' is invalid with technique = '"// &
                          trim(technique_name(opts%technique))//"' of &integration: "//trim(fix))
         return
      end do
      call check_braces(model, opts%technique, error)
      if (allocated(error)) return
      select case (opts%technique)
      case (technique_newmark)
         call newmark_check(model, exc, error)
      case (technique_event_driven)
         call modal_damping_check(model, opts%technique, error)
         if (.not. allocated(error)) call event_driven_check(model, exc, error)
      case (technique_moreau_jean)
         call modal_damping_check(model, opts%technique, error)
         if (.not. allocated(error)) call moreau_jean_check(model, exc, opts, error)
      case default
         call unknown_technique(opts%technique, error)
      end select
      if (allocated(error)) return
      ! the refinement's steps: bounded work, digits left in the effective stiffness
      traits = technique_traits(opts%technique)
      if (traits%refines_steps) call check_step_limits(model, exc, opts, error)
   end subroutine check_technique

   !> 'modal' damping (a low-rank C, fd_modal_damping) is integrated by Newmark alone: an
   !> error for the techniques that take C = a0 M + a1 K only.
   subroutine modal_damping_check(model, technique, error)
      type(model_type), intent(in) :: model         !! the model
      integer, intent(in) :: technique              !! the technique chosen
      type(error_type), allocatable, intent(out) :: error !! 'modal' damping with it

      if (model%damping /= damping_modal) return
      call fatal_error(error, "group &damping: damping_type = 'modal' is invalid with technique = '"// &
                       trim(technique_name(technique))//"': it is integrated by technique 'newmark' only; "// &
                       "give 'rayleigh' (xi at mode_i, mode_j), 'stiffness' or 'none'")
   end subroutine modal_damping_check

   !> The braces of the deck are hysteretic devices: an error naming &braces for a technique
   !> that does not integrate their law (the exact Coulomb techniques' devices are rigid while
   !> stuck); a brace of &floor_braces whose law the technique does not integrate, an error
   !> naming &floor_braces.
   subroutine check_braces(model, technique, error)
      type(model_type), intent(in) :: model         !! the model
      integer, intent(in) :: technique             !! the technique
      type(error_type), allocatable, intent(out) :: error !! a brace it cannot integrate
      integer :: d

      do d = 1, model%n_devices
         if (model%dev(d)%source == source_floor_brace .and. .not. technique_integrates(technique, &
                                                                                      model%dev(d)%law)) then
            call fatal_error(error, "group &floor_braces: law("//trim(fmt_int(model%dev(d)%source_index))// &
                             ") = '"//trim(law_name(model%dev(d)%law))//"' is invalid with technique = '"// &
                             trim(technique_name(technique))//"' of &integration: it integrates 'coulomb' "// &
                             "braces (rigid while stuck); set law = 'coulomb' or technique = 'newmark'")
            return
         end if
         if (model%dev(d)%source /= source_brace) cycle
         if (technique_integrates(technique, model%dev(d)%law)) cycle
         call fatal_error(error, "group &braces: brace "//trim(fmt_int(model%dev(d)%source_index))// &
                          " cannot be integrated with technique = '"//trim(technique_name(technique))// &
                          "' of &integration: a brace's elastic stiffness in series with the damper is the "// &
                          "sticking stiffness of the hysteretic law, which only technique = 'newmark' integrates "// &
                          "(the exact Coulomb techniques' devices are rigid while stuck); set technique = 'newmark'")
         return
      end do
   end subroutine check_braces

   !> Run the technique the settings choose (with the caller's control of the run, if any:
   !> history columns and destinations, stop requests, progress).
   subroutine run_technique(model, exc, opts, res, error, ctl, exc2, exc3)
      type(model_type), intent(in) :: model         !! validated model
      type(excitation_type), intent(in) :: exc      !! validated table motion
      type(integration_type), intent(in) :: opts    !! validated settings
      type(result_type), intent(out) :: res         !! histories and summary
      type(error_type), allocatable, intent(out) :: error !! what the technique cannot do, or
                                                          !! its failure
      type(run_control), intent(inout), target, optional :: ctl !! the run's control
      type(excitation_type), intent(in), optional :: exc2 !! a second horizontal component
                                                          !! (along the model's influence2)
      type(excitation_type), intent(in), optional :: exc3 !! the vertical component (bearings'
                                                          !! normal forces; Newmark and Moreau-Jean)

      if (opts%technique == technique_event_driven .and. given(exc2)) then
         call stepping_only("excitation2: a second horizontal component", opts%technique, &
                            "takes one component (&excitation)", error)
         return
      end if
      if (opts%technique == technique_event_driven .and. given(exc3)) then
         call stepping_only("excitation3: a vertical component (bearings' varying normal force)", opts%technique, &
                            "holds each bearing's p constant", error)
         return
      end if
      if (opts%technique /= technique_newmark .and. opts%linear_system == linear_system_sparse) then
         call fatal_error(error, "group &integration: linear_system = 'sparse' (CHOLMOD) is Newmark's; technique = '"// &
                          trim(technique_name(opts%technique))//"' takes 'auto', 'dense' or 'banded'")
         return
      end if
      if (opts%technique == technique_event_driven .and. model%overturning) then
         call stepping_only("bearings: overturning = .true. (bearings' varying normal force)", opts%technique, &
                            "holds each bearing's p constant", error)
         return
      end if
      select case (opts%technique)
      case (technique_newmark)
         call run_newmark(model, exc, opts, res, error, ctl, exc2, exc3)
      case (technique_event_driven)
         call run_event_driven(model, exc, opts, res, error, ctl)
      case (technique_moreau_jean)
         call run_moreau_jean(model, exc, opts, res, error, ctl, exc2, exc3)
      case default
         call unknown_technique(opts%technique, error)
      end select
      ! whether the step resolves the highest modes: one report for every stepping technique
      if (.not. allocated(error)) call mode_resolution(model, res, error)
      ! and the table's motion: a harmonic's frequency, a record's spectrum
      if (.not. allocated(error)) call harmonic_resolution(model, opts%beta, opts%gamma, opts%theta, res, error)
      if (.not. allocated(error)) call record_resolution(model, exc, opts%beta, opts%gamma, opts%theta, res, error)
   end subroutine run_technique

   !> Whether an optional table motion's component is given (present, and of a kind).
   pure logical function given(exc)
      type(excitation_type), intent(in), optional :: exc !! the component

      given = present(exc)
      if (given) given = exc%kind /= excitation_none
   end function given

   !> The error of an input that the time-stepping techniques integrate and this one does
   !> not: "group &<what> is integrated by technique = 'newmark' or 'moreau_jean'; technique
   !> = '<technique>' <instead>".
   subroutine stepping_only(what, technique, instead, error)
      character(len=*), intent(in) :: what          !! the group, its variable or component
      integer, intent(in) :: technique              !! the technique chosen
      character(len=*), intent(in) :: instead       !! what the technique does instead
      type(error_type), allocatable, intent(out) :: error !! the error

      call fatal_error(error, "group &"//what//" is integrated by technique = 'newmark' or 'moreau_jean'; "// &
                       "technique = '"//trim(technique_name(technique))//"' "//instead)
   end subroutine stepping_only

   subroutine unknown_technique(technique, error)
      integer, intent(in) :: technique
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: choices

      call keyword_choices(techniques, choices)
      call fatal_error(error, "group &integration: technique (id "//trim(fmt_int(technique))// &
                       ") is not a technique of this build; one of "//choices)
   end subroutine unknown_technique

end module fd_technique
