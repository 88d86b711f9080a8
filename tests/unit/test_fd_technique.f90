!> Unit tests of the technique dispatch (fd_technique) and of the friction dispatch
!> (fd_friction): law and technique are separate settings, and whatever a technique or the
!> friction dispatch cannot integrate is an error naming the variable, never a device
!> without force or an unforced structure.
module test_fd_technique
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_model, only: model_type, device_type, integration_type, law_velocity, law_hysteretic, law_coulomb, &
                       technique_newmark, technique_event_driven, technique_moreau_jean
   use fd_excitation, only: excitation_type, excitation_harmonic
   use fd_result, only: result_type
   use fd_device_state, only: device_state, phase_stick
   use fd_friction, only: friction_init
   use fd_technique, only: check_technique, run_technique
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
                  new_unittest("friction dispatch: a law it lacks", test_friction_dispatch) &
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

end module test_fd_technique
