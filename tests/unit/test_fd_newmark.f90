!> Unit tests of Newmark's time-step loop (fd_newmark) on a two-mass model: the step takes
!> devices between two nodes by their nodes (pair_loads, pair_motion) and any other direction
!> through fd_kinematics (device_loads, relative_motion); both give the same run to the bit.
module test_fd_newmark
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use test_fd_helpers, only: pairs_of
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_model, only: model_type, device_type, integration_type, law_velocity, law_hysteretic, technique_newmark
   use fd_excitation, only: excitation_type, excitation_harmonic
   use fd_kinematics, only: devices_are_pairs
   use fd_result, only: result_type
   use fd_newmark, only: run_newmark
   implicit none
   private

   public :: collect_newmark

contains

   subroutine collect_newmark(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("devices by their nodes and by their terms: the same run", test_pairs_and_terms) &
                  ]
   end subroutine collect_newmark

   !> Two masses on springs to the table, a hysteretic device between them and a velocity-law
   !> device from the second to the table, under a harmonic table motion that makes both slide.
   subroutine setup(model, exc, opts)
      type(model_type), intent(out) :: model
      type(excitation_type), intent(out) :: exc
      type(integration_type), intent(out) :: opts

      model%n_dof = 2
      model%mass = [6.3_dp, 2.5_dp]
      model%u0 = [0.0_dp, 0.0_dp]
      model%v0 = [0.0_dp, 0.0_dp]
      model%n_springs = 2
      model%spring_i = [1, 2]
      model%spring_j = [0, 0]
      model%spring_k = [1084.0_dp, 2895.0_dp]
      model%n_devices = 2
      model%dev = [device_type(node_i=2, node_j=0, law=law_hysteretic, p=20.0_dp, mu=0.1_dp, f=1.0e-5_dp, &
                               eps1=1.0e-3_dp), &
                   device_type(node_i=1, node_j=2, law=law_velocity, p=61.81_dp, mu=0.22_dp, eps=1.0e-3_dp)]
      call pairs_of(model)
      exc%kind = excitation_harmonic
      exc%amplitude = 0.004_dp
      exc%frequency = 4.1_dp
      exc%dt_record = 0.005_dp
      exc%duration = 1.0_dp
      opts%technique = technique_newmark
      opts%n1 = 10
      opts%n2 = 20
   end subroutine setup

   !> The same model with the terms of device 2 in the other order (-e_2 + e_1: no longer read
   !> as a pair of nodes, so the whole step goes through fd_kinematics' terms) gives the same
   !> history, peaks, transitions and energies to the bit as the step by the nodes. Both
   !> devices slide, stick and reverse in the run (the comparison covers each law's phases).
   subroutine test_pairs_and_terms(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(result_type) :: by_nodes, by_terms
      type(fd_error_type), allocatable :: err

      call setup(model, exc, opts)
      call check(error, devices_are_pairs(model), "the model's devices join two nodes")
      if (allocated(error)) return
      call run_newmark(model, exc, opts, by_nodes, err)
      if (allocated(err)) then
         call test_failed(error, "by the nodes: "//err%message); return
      end if
      call check(error, all(by_nodes%stick_to_slip > 0) .and. all(by_nodes%slip_to_stick > 0), &
                 "both devices slide and stick again")
      if (allocated(error)) return
      ! device 2 as -e_2 + e_1 (the last device: the checks that take devices as links still
      ! find device 1's nodes); the nodes kept for the pairs go with the directions they were
      ! made from
      model%dev_dof(2:3) = [2, 1]
      model%dev_coef(2:3) = [-1.0_dp, 1.0_dp]
      deallocate (model%dev_nodes)
      call check(error, .not. devices_are_pairs(model), "device 2 is no longer read as a pair")
      if (allocated(error)) return
      call run_newmark(model, exc, opts, by_terms, err)
      if (allocated(err)) then
         call test_failed(error, "by the terms: "//err%message); return
      end if
      call check(error, all(shape(by_terms%hist) == shape(by_nodes%hist)), "history shapes")
      if (allocated(error)) return
      call check(error, all(by_terms%hist == by_nodes%hist), "histories equal to the bit")
      if (allocated(error)) return
      call check(error, all(by_terms%peak_u == by_nodes%peak_u) .and. all(by_terms%peak_aabs == by_nodes%peak_aabs) &
                 .and. all(by_terms%peak_s == by_nodes%peak_s) .and. all(by_terms%peak_force == by_nodes%peak_force), &
                 "peaks equal to the bit")
      if (allocated(error)) return
      call check(error, all(by_terms%stick_to_slip == by_nodes%stick_to_slip) .and. &
                 all(by_terms%slip_to_stick == by_nodes%slip_to_stick) .and. &
                 all(by_terms%reversals == by_nodes%reversals), "transitions")
      if (allocated(error)) return
      call check(error, by_terms%e_input == by_nodes%e_input .and. by_terms%e_viscous == by_nodes%e_viscous .and. &
                 by_terms%e_device == by_nodes%e_device .and. by_terms%e_friction == by_nodes%e_friction, &
                 "energies equal to the bit")
   end subroutine test_pairs_and_terms

end module test_fd_newmark
