!> Unit tests of the technique dispatch (fd_technique) and of the friction dispatch
!> (fd_friction): law and technique are separate settings, and whatever a technique or the
!> friction dispatch cannot integrate is an error naming the variable, never a device
!> without force or an unforced structure.
module test_fd_technique
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use test_fd_helpers, only: pairs_of
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type, fmt_int
   use fd_model, only: model_type, device_type, integration_type, law_velocity, law_hysteretic, law_coulomb, &
                       technique_newmark, technique_event_driven, technique_moreau_jean, source_brace
   use fd_names, only: techniques, laws, rule_none, rule_newmark, rule_theta
   use fd_excitation, only: excitation_type, excitation_harmonic, excitation_none
   use fd_result, only: result_type
   use fd_device_state, only: device_state, phase_stick
   use fd_friction, only: friction_init
   use fd_technique, only: check_technique, run_technique, technique_traits_type, technique_traits, &
                           technique_integrates, technique_step_rule
   use fd_step_limits, only: max_refinement
   implicit none
   private

   public :: collect_technique

contains

   subroutine collect_technique(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("valid combinations", test_valid), &
                  new_unittest("coulomb under newmark", test_coulomb_newmark), &
                  new_unittest("regularized law under event_driven", test_velocity_event_driven), &
                  new_unittest("moreau_jean: coulomb only, theta in range", test_moreau_jean), &
                  new_unittest("unknown technique", test_unknown_technique), &
                  new_unittest("unknown excitation", test_unknown_excitation), &
                  new_unittest("friction dispatch: a law it lacks", test_friction_dispatch), &
                  new_unittest("a general device: every technique takes it", test_general_device), &
                  new_unittest("traits of each technique", test_traits), &
                  new_unittest("the laws each technique integrates", test_integrates), &
                  new_unittest("a brace under an exact Coulomb technique", test_braces), &
                  new_unittest("newmark: the refinement's limits", test_refinement_limits), &
                  new_unittest("event_driven: a second or vertical component, overturning", test_stepping_only) &
                  ]
   end subroutine collect_technique

   !> Two masses, two devices of the given laws, harmonic table motion.
   subroutine setup(law1, law2, model, exc)
      integer, intent(in) :: law1, law2
      type(model_type), intent(out) :: model
      type(excitation_type), intent(out) :: exc

      model%n_dof = 2
      model%mass = [2.0_dp, 1.0_dp]
      model%u0 = [0.0_dp, 0.0_dp]
      model%v0 = [0.0_dp, 0.0_dp]
      model%n_springs = 2
      model%spring_i = [1, 2]
      model%spring_j = [0, 1]
      model%spring_k = [800.0_dp, 300.0_dp]
      model%n_devices = 2
      model%dev = [device_type(node_i=1, node_j=0, law=law1, p=10.0_dp, mu=0.2_dp), &
                   device_type(node_i=2, node_j=1, law=law2, p=5.0_dp, mu=0.2_dp)]
      call pairs_of(model)
      exc%kind = excitation_harmonic
      exc%amplitude = 0.01_dp
      exc%frequency = 2.0_dp
      exc%dt_record = 0.01_dp
      exc%duration = 0.05_dp
   end subroutine setup

   !> Error expected, with every word in its message.
   subroutine expect(err, words, error)
      type(fd_error_type), allocatable, intent(in) :: err
      character(len=*), intent(in) :: words(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: i

      if (.not. allocated(err)) then
         call test_failed(error, "no error"); return
      end if
      do i = 1, size(words)
         if (index(err%message, trim(words(i))) == 0) then
            call test_failed(error, "'"//trim(words(i))//"' not in: "//err%message); return
         end if
      end do
   end subroutine expect

   subroutine test_valid(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(fd_error_type), allocatable :: err

      call setup(law_velocity, law_hysteretic, model, exc)
      opts%technique = technique_newmark
      call check_technique(model, exc, opts, err)
      call check(error, .not. allocated(err), "regularized laws under newmark")
      if (allocated(error)) return
      call setup(law_coulomb, law_coulomb, model, exc)
      opts%technique = technique_event_driven
      call check_technique(model, exc, opts, err)
      call check(error, .not. allocated(err), "coulomb under event_driven")
      if (allocated(error)) return
      ! no devices: both techniques integrate the linear structure
      model%n_devices = 0
      model%dev = model%dev(1:0)
      call pairs_of(model)
      call check_technique(model, exc, opts, err)
      call check(error, .not. allocated(err), "no devices under event_driven")
   end subroutine test_valid

   subroutine test_coulomb_newmark(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(result_type) :: res
      type(fd_error_type), allocatable :: err

      call setup(law_velocity, law_coulomb, model, exc)
      opts%technique = technique_newmark
      call check_technique(model, exc, opts, err)
      call expect(err, [character(len=40) :: "group &friction", "law(2) = 'coulomb'", "technique = 'newmark'", &
                        "set technique = 'event_driven'", "'velocity', 'hysteretic'"], error)
      if (allocated(error)) return
      ! the run itself refuses too (a caller that skips the check)
      call run_technique(model, exc, opts, res, err)
      call expect(err, [character(len=40) :: "law(2) = 'coulomb'"], error)
   end subroutine test_coulomb_newmark

   subroutine test_velocity_event_driven(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(result_type) :: res
      type(fd_error_type), allocatable :: err

      call setup(law_coulomb, law_velocity, model, exc)
      opts%technique = technique_event_driven
      call check_technique(model, exc, opts, err)
      call expect(err, [character(len=40) :: "group &friction", "law(2) = 'velocity'", &
                        "technique = 'event_driven'", "law(2) = 'coulomb'", "technique = 'newmark'"], error)
      if (allocated(error)) return
      call run_technique(model, exc, opts, res, err)
      call expect(err, [character(len=40) :: "law(2) = 'velocity'"], error)
   end subroutine test_velocity_event_driven

   !> Moreau-Jean integrates 'coulomb' devices (the two-mass set-up runs, its technique
   !> recorded), refuses a regularized law naming what to set, and theta outside [1/2, 1].
   subroutine test_moreau_jean(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(result_type) :: res
      type(fd_error_type), allocatable :: err

      call setup(law_coulomb, law_coulomb, model, exc)
      opts%technique = technique_moreau_jean
      call run_technique(model, exc, opts, res, err)
      call check(error, .not. allocated(err), "coulomb under moreau_jean runs")
      if (allocated(error)) return
      call check(error, res%technique == technique_moreau_jean .and. res%moreau_jean%steps == 100, "its steps")
      if (allocated(error)) return
      call setup(law_coulomb, law_hysteretic, model, exc)
      call check_technique(model, exc, opts, err)
      call expect(err, [character(len=40) :: "group &friction", "law(2) = 'hysteretic'", &
                        "technique = 'moreau_jean'", "law(2) = 'coulomb'", "technique = 'newmark'"], error)
      if (allocated(error)) return
      call setup(law_coulomb, law_coulomb, model, exc)
      opts%theta = 0.45_dp
      call check_technique(model, exc, opts, err)
      call expect(err, [character(len=40) :: "&integration", "theta = 0.45", "between 0.5 and 1"], error)
   end subroutine test_moreau_jean

   subroutine test_unknown_technique(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(result_type) :: res
      type(fd_error_type), allocatable :: err

      call setup(law_velocity, law_velocity, model, exc)
      opts%technique = 99
      call check_technique(model, exc, opts, err)
      call expect(err, [character(len=40) :: "&integration", "technique (id 99)", "'newmark'", "'event_driven'", &
                        "'moreau_jean'"], error)
      if (allocated(error)) return
      call run_technique(model, exc, opts, res, err)
      call expect(err, [character(len=40) :: "technique (id 99)"], error)
   end subroutine test_unknown_technique

   !> A table motion the exact technique has no exact form of is an error, not an
   !> unforced structure; Newmark refuses an excitation id outside the table too.
   subroutine test_unknown_excitation(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(fd_error_type), allocatable :: err

      call setup(law_coulomb, law_coulomb, model, exc)
      exc%kind = 42
      opts%technique = technique_event_driven
      call check_technique(model, exc, opts, err)
      call expect(err, [character(len=40) :: "&excitation", "excitation_type", "technique = 'newmark'"], error)
      if (allocated(error)) return
      call setup(law_velocity, law_velocity, model, exc)
      exc%kind = 42
      opts%technique = technique_newmark
      call check_technique(model, exc, opts, err)
      call expect(err, [character(len=40) :: "&excitation", "excitation_type"], error)
   end subroutine test_unknown_excitation

   !> The friction dispatch has a case for each regularized law and an error for any other:
   !> a device can never silently get F = 0.
   subroutine test_friction_dispatch(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(device_state) :: st(2)
      type(fd_error_type), allocatable :: err

      call setup(law_velocity, law_hysteretic, model, exc)
      call friction_init(model%dev, [0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], st, err)
      call check(error, .not. allocated(err), "regularized laws: unexpected error")
      if (allocated(error)) return
      ! velocity law sticking: F = (P mu / eps) s'; hysteretic sticking: F = (P mu / f)(s - c)
      call check(error, st(1)%phase == phase_stick .and. st(1)%cs == 10.0_dp*0.2_dp/1.0e-3_dp .and. &
                 st(2)%ks == 5.0_dp*0.2_dp/1.0e-5_dp, "initial coefficients")
      if (allocated(error)) return
      model%dev(2)%law = law_coulomb
      call friction_init(model%dev, [0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], st, err)
      call expect(err, [character(len=40) :: "device 2", "'coulomb'"], error)
      if (allocated(error)) return
      model%dev(1)%law = 77
      call friction_init(model%dev, [0.0_dp, 0.0_dp], [0.0_dp, 0.0_dp], st, err)
      call expect(err, [character(len=40) :: "device 1", "id 77"], error)
   end subroutine test_friction_dispatch

   !> Each technique's traits as documented (fd_names, fd_technique): Newmark integrates the
   !> regularized laws with its own step rule and refines its steps; the exact technique
   !> integrates Coulomb's law with no step and rows that carry the maxima since the last
   !> one; Moreau-Jean integrates Coulomb's law with the theta-method. An id without a row
   !> integrates nothing and takes no step; every technique of the names table has a row.
   subroutine test_traits(error)
      type(error_type), allocatable, intent(out) :: error
      type(technique_traits_type) :: t
      integer :: k

      t = technique_traits(technique_newmark)
      call check(error, t%regularized_laws .and. .not. t%set_valued_laws .and. t%step_rule == rule_newmark .and. &
                 t%refines_steps .and. .not. t%envelope, "newmark")
      if (allocated(error)) return
      t = technique_traits(technique_event_driven)
      call check(error, .not. t%regularized_laws .and. t%set_valued_laws .and. t%step_rule == rule_none .and. &
                 .not. t%refines_steps .and. t%envelope, "event_driven")
      if (allocated(error)) return
      t = technique_traits(technique_moreau_jean)
      call check(error, .not. t%regularized_laws .and. t%set_valued_laws .and. t%step_rule == rule_theta .and. &
                 .not. t%refines_steps .and. .not. t%envelope, "moreau_jean")
      if (allocated(error)) return
      do k = 0, size(techniques) + 1, size(techniques) + 1
         t = technique_traits(k)
         call check(error, .not. (t%regularized_laws .or. t%set_valued_laws .or. t%refines_steps .or. t%envelope) &
                    .and. technique_step_rule(k) == rule_none, "an id without a row has no traits")
         if (allocated(error)) return
      end do
      do k = 1, size(techniques)
         t = technique_traits(k)
         call check(error, t%regularized_laws .or. t%set_valued_laws, &
                    "technique '"//trim(techniques(k)%name)//"' has traits (integrates a law)")
         if (allocated(error)) return
      end do
   end subroutine test_traits

   subroutine test_integrates(error)
      type(error_type), allocatable, intent(out) :: error

      call check(error, technique_integrates(technique_newmark, law_velocity) .and. &
                 technique_integrates(technique_newmark, law_hysteretic) .and. &
                 .not. technique_integrates(technique_newmark, law_coulomb), "newmark: the regularized laws")
      if (allocated(error)) return
      call check(error, technique_integrates(technique_event_driven, law_coulomb) .and. &
                 .not. technique_integrates(technique_event_driven, law_velocity) .and. &
                 .not. technique_integrates(technique_event_driven, law_hysteretic), "event_driven: coulomb")
      if (allocated(error)) return
      call check(error, technique_integrates(technique_moreau_jean, law_coulomb) .and. &
                 .not. technique_integrates(technique_moreau_jean, law_velocity), "moreau_jean: coulomb")
      if (allocated(error)) return
      call check(error, .not. technique_integrates(technique_newmark, 0) .and. &
                 .not. technique_integrates(technique_newmark, size(laws) + 1) .and. &
                 .not. technique_integrates(99, law_velocity), "no unknown law, no unknown technique")
   end subroutine test_integrates

   !> A brace (a hysteretic device of &braces) is refused by name under a technique that does
   !> not integrate its law, before the technique's own check of the law; Newmark takes it.
   subroutine test_braces(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(fd_error_type), allocatable :: err

      call setup(law_coulomb, law_hysteretic, model, exc)
      model%dev(2)%source = source_brace
      model%dev(2)%source_index = 1
      opts%technique = technique_event_driven
      call check_technique(model, exc, opts, err)
      call expect(err, [character(len=40) :: "group &braces: brace 1", "technique = 'event_driven'", &
                        "set technique = 'newmark'"], error)
      if (allocated(error)) return
      opts%technique = technique_moreau_jean
      call check_technique(model, exc, opts, err)
      call expect(err, [character(len=40) :: "group &braces: brace 1", "technique = 'moreau_jean'"], error)
      if (allocated(error)) return
      model%dev(1)%law = law_velocity
      opts%technique = technique_newmark
      call check_technique(model, exc, opts, err)
      call check(error, .not. allocated(err), "a brace under newmark")
   end subroutine test_braces

   !> The technique that refines its steps checks the refinement's limits (fd_step_limits).
   subroutine test_refinement_limits(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(fd_error_type), allocatable :: err

      call setup(law_velocity, law_hysteretic, model, exc)
      opts%technique = technique_newmark
      opts%n2 = max_refinement + 1
      call check_technique(model, exc, opts, err)
      call expect(err, [character(len=40) :: "group &integration: n2 = ", "at most"], error)
   end subroutine test_refinement_limits

   !> The exact techniques refuse a device along a general direction (their phase patterns
   !> and sticking groups take devices as links between two nodes); Newmark takes it.
   subroutine test_general_device(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(fd_error_type), allocatable :: err
      integer, parameter :: exact(2) = [technique_event_driven, technique_moreau_jean]
      integer :: t

      ! the exact Coulomb techniques take a device of any direction b (their general patterns
      ! and dense one-step problem), with the law they integrate
      call setup(law_coulomb, law_coulomb, model, exc)
      model%dev_coef(1) = 0.6_dp
      do t = 1, 2
         opts%technique = exact(t)
         call check_technique(model, exc, opts, err)
         call check(error, .not. allocated(err), "technique "//trim(fmt_int(exact(t)))// &
                    " refuses a Coulomb device of a general direction")
         if (allocated(error)) return
      end do
      call setup(law_velocity, law_velocity, model, exc)
      model%dev_coef(1) = 0.6_dp
      opts%technique = technique_newmark
      call check_technique(model, exc, opts, err)
      call check(error, .not. allocated(err), "newmark refuses a device of a general direction")
   end subroutine test_general_device

   !> The exact event-driven technique refuses what the time-stepping techniques alone
   !> integrate: a second horizontal component, a vertical one, the bearings' overturning;
   !> each message names the group, the variable or component and what the technique does
   !> instead. An absent or 'none' component is no refusal.
   subroutine test_stepping_only(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc, none
      type(integration_type) :: opts
      type(result_type) :: res
      type(fd_error_type), allocatable :: err
      character(len=*), parameter :: by = " is integrated by technique = 'newmark' or 'moreau_jean'; " // &
                                           "technique = 'event_driven' "

      call setup(law_coulomb, law_coulomb, model, exc)
      opts%technique = technique_event_driven
      none%kind = excitation_none
      call run_technique(model, exc, opts, res, err, exc2=exc)
      call check(error, allocated(err), "a second component taken")
      if (allocated(error)) return
      call check(error, err%message, "group &excitation2: a second horizontal component"//by// &
                 "takes one component (&excitation)")
      if (allocated(error)) return
      call run_technique(model, exc, opts, res, err, exc2=none, exc3=exc)
      call check(error, allocated(err), "a vertical component taken")
      if (allocated(error)) return
      call check(error, err%message, "group &excitation3: a vertical component (bearings' varying normal force)"// &
                 by//"holds each bearing's p constant")
      if (allocated(error)) return
      model%overturning = .true.
      call run_technique(model, exc, opts, res, err, exc2=none, exc3=none)
      call check(error, allocated(err), "overturning taken")
      if (allocated(error)) return
      call check(error, err%message, "group &bearings: overturning = .true. (bearings' varying normal force)"// &
                 by//"holds each bearing's p constant")
      if (allocated(error)) return
      model%overturning = .false.
      call run_technique(model, exc, opts, res, err, exc2=none, exc3=none)
      call check(error, .not. allocated(err), "components of kind 'none' refused")
   end subroutine test_stepping_only

end module test_fd_technique
