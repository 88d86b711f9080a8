!> Whether the main step of a stepping technique resolves the structure's highest natural
!> modes: omega_max dt1 against 2 (fewer than pi steps in the shortest period).
!>
!> Newmark's average acceleration and Moreau-Jean's theta = 1/2 are unconditionally stable:
!> a mode with omega dt1 >> 1 stays bounded, but with the wrong period (the trapezoidal rule
!> gives 2 atan(omega dt / 2) / dt: 27 % too long at omega dt = 2, and never above pi / dt)
!> and no numerical damping. A friction transition excites every mode near its device, so
!> the absolute accelerations then carry a spurious response of those modes (6 times the
!> resolved peak at 10 000 storeys and dt1 = 1 ms): the summary says so, and the
!> executable and the command line print a warning. It is a report, not an error: drifts
!> and shears are dominated by the low modes, which the step resolves.
!>
!> The system integrated at dt1: the springs, and the devices' sticking springs (the
!> hysteretic law's P mu / f, the stiffest phase); velocity-law devices add damping, not
!> stiffness, and rigid (Coulomb) links only lower the highest frequency (a constraint
!> cannot raise the largest eigenvalue), so neither enters. The event-driven technique has no
!> step: not applicable.
module fd_mode_resolution
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, stat_no_memory
   use fd_names, only: technique_step_rule, rule_none
   use fd_model, only: model_type
   use fd_friction, only: sticking_stiffness
   use fd_kinematics, only: pair_nodes
   use fd_modes, only: highest_eigenvalue
   use fd_result, only: result_type, resolution_none, resolution_resolved, resolution_unresolved
   implicit none
   private

   public :: mode_resolution, resolution_limit

   !> omega_max dt1 above which the highest modes are not resolved (pi steps a period).
   real(dp), parameter :: resolution_limit = 2.0_dp

contains

   !> Sets res%omega_max (the highest natural circular frequency of the system the technique
   !> integrates at dt1, a lower bound accurate to 1e-4: fd_modes' Lanczos) and
   !> res%mode_resolution, from res%technique and res%dt1.
   subroutine mode_resolution(model, res, error)
      type(model_type), intent(in) :: model               !! the model
      type(result_type), intent(inout) :: res             !! the result of the run
      type(error_type), allocatable, intent(out) :: error !! no memory, solver failure
      integer, allocatable :: ei(:), ej(:)
      real(dp), allocatable :: ek(:)
      real(dp) :: lam, bound, kd
      integer :: ns, nd, ne, d, stat

      res%mode_resolution = resolution_none
      res%omega_max = 0.0_dp
      if (technique_step_rule(res%technique) == rule_none) return
      if (res%dt1 <= 0.0_dp .or. model%n_dof == 0) return
      ns = model%n_springs
      nd = model%n_devices
      allocate (ei(ns + nd), ej(ns + nd), ek(ns + nd), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "the highest natural frequency: not enough memory for "// &
                          trim(fmt_int(ns + nd))//" elements", stat_no_memory)
         return
      end if
      ei(1:ns) = model%spring_i(1:ns)
      ej(1:ns) = model%spring_j(1:ns)
      ek(1:ns) = model%spring_k(1:ns)
      ne = ns
      ! the sticking springs (the Coulomb devices of the theta-method's steps have none)
      do d = 1, nd
         kd = sticking_stiffness(model%dev(d))
         if (kd <= 0.0_dp) cycle
         ne = ne + 1
         call pair_nodes(model, d, ei(ne), ej(ne))
         ek(ne) = kd
      end do
      call highest_eigenvalue(model%mass, ei(1:ne), ej(1:ne), ek(1:ne), lam, bound, error)
      if (allocated(error)) then
         error%message = "the highest natural frequency: "//error%message
         return
      end if
      res%omega_max = sqrt(max(lam, 0.0_dp))
      if (res%omega_max*res%dt1 > resolution_limit) then
         res%mode_resolution = resolution_unresolved
      else
         res%mode_resolution = resolution_resolved
      end if
   end subroutine mode_resolution

end module fd_mode_resolution
