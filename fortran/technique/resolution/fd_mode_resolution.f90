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
!> cannot raise the largest eigenvalue), so neither enters. A bearing whose normal force N
!> varies (a vertical component, the overturning) enters at the largest N of the run (the
!> summary's bearing N_max, every accepted state): its sticking spring N_max mu / f and a
!> friction pendulum's stiffness beyond K's, (N_max - p_static) / R. (The techniques apply
!> that last stiffness as a force lagged one step, not in their system matrix; it is in the
!> structure's motion all the same, and counting it errs on the safe side.) The
!> event-driven technique has no step: not applicable.
module fd_mode_resolution
   use fd_kinds, only: dp
   use fd_error, only: error_type, fmt_int, allocation_error
   use fd_names, only: technique_step_rule, rule_none
   use fd_model, only: model_type, device_type
   use fd_friction, only: sticking_stiffness
   use fd_friction_planar, only: pendulum_excess
   use fd_kinematics, only: pair_nodes, devices_are_pairs, add_device_outer
   use fd_matrices, only: stiffness_matrix, modes_dense_dofs
   use fd_linalg, only: generalized_eigen
   use fd_modes, only: highest_eigenvalue, general_highest_eigenvalue
   use fd_result, only: result_type, run_setup, setup_of, resolution_limit => mode_resolution_limit
   implicit none
   private

   !> resolution_limit: omega_max dt1 above which the highest modes are not resolved (pi
   !> steps a period), fd_result's mode_resolution_limit, by which fd_warnings judges
   public :: mode_resolution, resolution_limit

contains

   !> Sets res%omega_max (the highest natural circular frequency of the system the technique
   !> integrates at dt1, a lower bound accurate to 1e-4: fd_modes' Lanczos) and
   !> res%mode_checked, from res%technique and its dt1; the verdict is the check's
   !> (fd_warnings: omega_max dt1 against resolution_limit).
   subroutine mode_resolution(model, res, error)
      type(model_type), intent(in) :: model               !! the model
      type(result_type), intent(inout) :: res             !! the result of the run
      type(error_type), allocatable, intent(out) :: error !! no memory, solver failure
      integer, allocatable :: ei(:), ej(:)
      real(dp), allocatable :: ek(:), kd(:)
      real(dp) :: lam, bound
      integer :: ns, nd, ne, d, stat
      type(run_setup) :: setup

      res%mode_checked = .false.
      res%omega_max = 0.0_dp
      setup = setup_of(res)
      if (technique_step_rule(res%technique) == rule_none) return
      if (setup%dt1 <= 0.0_dp .or. model%n_dof == 0) return
      ns = model%n_springs
      nd = model%n_devices
      allocate (kd(nd), stat=stat)
      call allocation_error(error, stat, "the highest natural frequency's "//trim(fmt_int(nd))//" sticking springs")
      if (allocated(error)) return
      call largest_sticking(model, res, kd)
      if (model%n_kx > 0 .or. .not. devices_are_pairs(model)) then
         ! stiffness beyond springs, or devices of any direction: the dense eigenproblem up to
         ! modes_dense_dofs DOFs, else Lanczos on the matrices' entries (no n x n matrix)
         if (model%n_dof <= modes_dense_dofs) then
            call dense_highest(model, kd, lam, error)
         else
            call general_highest(model, kd, lam, error)
         end if
         if (allocated(error)) return
         res%omega_max = sqrt(max(lam, 0.0_dp))
         res%mode_checked = .true.
         return
      end if
      allocate (ei(ns + nd), ej(ns + nd), ek(ns + nd), stat=stat)
      call allocation_error(error, stat, "the highest natural frequency's "//trim(fmt_int(ns + nd))//" elements")
      if (allocated(error)) return
      ei(1:ns) = model%spring_i(1:ns)
      ej(1:ns) = model%spring_j(1:ns)
      ek(1:ns) = model%spring_k(1:ns)
      ne = ns
      ! the sticking springs (the Coulomb devices of the theta-method's steps have none)
      do d = 1, nd
         if (kd(d) <= 0.0_dp) cycle
         ne = ne + 1
         call pair_nodes(model, d, ei(ne), ej(ne))
         ek(ne) = kd(d)
      end do
      call highest_eigenvalue(model%mass, ei(1:ne), ej(1:ne), ek(1:ne), lam, bound, error)
      if (allocated(error)) then
         error%message = "the highest natural frequency: "//error%message
         return
      end if
      res%omega_max = sqrt(max(lam, 0.0_dp))
      res%mode_checked = .true.
   end subroutine mode_resolution

   !> Each device's largest sticking spring over the run [N/m]: sticking_stiffness at the
   !> deck's p; a bearing's at the largest normal force N_max of the run (res%bearing_n_max,
   !> every accepted state: a vertical component's N0 (1 + a_z / g) and the overturning's dN),
   !> plus a friction pendulum's stiffness beyond the one K holds, (N_max - p_static) / R when
   !> positive. The hysteretic law's P mu / f scales with N: at the deck's p, omega_max would
   !> be understated by up to sqrt(N_max / p).
   pure subroutine largest_sticking(model, res, kd)
      type(model_type), intent(in) :: model         !! the model
      type(result_type), intent(in) :: res          !! the run's result (its bearings' N_max)
      real(dp), intent(out) :: kd(:)                !! (n_devices) sticking springs [N/m]
      type(device_type) :: dv
      integer :: b, c, d

      kd = max(sticking_stiffness(model%dev(1:size(kd))), 0.0_dp)
      if (.not. allocated(res%bearing_n_max)) return
      do b = 1, res%n_bearings
         do c = 1, 2
            d = res%bearing_dev(c, b)
            dv = model%dev(d)
            dv%p = max(res%bearing_n_max(b), 0.0_dp)
            kd(d) = max(sticking_stiffness(dv), 0.0_dp) + max(pendulum_excess(dv), 0.0_dp)
         end do
      end do
   end subroutine largest_sticking

   !> The largest eigenvalue w^2 of (K + the sticking springs' k_d b_d b_d', M) of a general
   !> model by fd_modes' Lanczos on the entries (a lower bound accurate to 1e-10 relative).
   subroutine general_highest(model, kd, lam, error)
      type(model_type), intent(in) :: model               !! the model
      real(dp), intent(in) :: kd(:)                       !! (n_devices) sticking springs [N/m]
      real(dp), intent(out) :: lam                        !! largest w^2 [1/s2]
      type(error_type), allocatable, intent(out) :: error !! no memory, solver failure
      real(dp) :: bound
      integer :: ns, nk

      ns = model%n_springs
      nk = model%n_kx
      if (nk == 0) then
         call general_highest_eigenvalue(model%mass, model%spring_i(1:ns), model%spring_j(1:ns), &
                                         model%spring_k(1:ns), [integer ::], [integer ::], [real(dp) ::], &
                                         model%dev_ptr, model%dev_dof, model%dev_coef, &
                                         kd, lam, bound, error)
      else
         call general_highest_eigenvalue(model%mass, model%spring_i(1:ns), model%spring_j(1:ns), &
                                         model%spring_k(1:ns), model%kx_i(1:nk), model%kx_j(1:nk), &
                                         model%kx_v(1:nk), model%dev_ptr, model%dev_dof, model%dev_coef, &
                                         kd, lam, bound, error)
      end if
      if (allocated(error)) error%message = "the highest natural frequency: "//error%message
   end subroutine general_highest

   !> The largest eigenvalue w^2 of (K + the sticking springs' k_d b_d b_d', M) of a general
   !> model, from the dense generalized eigenproblem.
   subroutine dense_highest(model, kd, lam, error)
      type(model_type), intent(in) :: model               !! the model
      real(dp), intent(in) :: kd(:)                       !! (n_devices) sticking springs [N/m]
      real(dp), intent(out) :: lam                        !! largest w^2 [1/s2]
      type(error_type), allocatable, intent(out) :: error !! no memory, solver failure
      real(dp), allocatable :: k(:, :), m(:, :), w(:), z(:, :)
      integer :: n, d, i, stat

      n = model%n_dof
      lam = 0.0_dp
      allocate (k(n, n), m(n, n), w(n), z(n, n), stat=stat)
      call allocation_error(error, stat, "the highest natural frequency's dense matrices of "//trim(fmt_int(n))// &
                            " DOFs")
      if (allocated(error)) return
      call stiffness_matrix(model, k)
      do d = 1, model%n_devices
         if (kd(d) > 0.0_dp) call add_device_outer(model, d, kd(d), k)
      end do
      m = 0.0_dp
      do i = 1, n
         m(i, i) = model%mass(i)
      end do
      call generalized_eigen(k, m, w, z, error)
      if (allocated(error)) then
         error%message = "the highest natural frequency: "//error%message
         return
      end if
      lam = w(n)
   end subroutine dense_highest

end module fd_mode_resolution
