!> Whether the main step resolves a harmonic table motion: the error the step alone makes in
!> the linear steady state of the structure at the table's frequency, for the stuck and the
!> free system, from closed forms (Newmark).
!>
!> Under a harmonic table motion sampled at the steps, a linear system integrated by Newmark's
!> method has a steady state whose amplitude follows in closed form from the recursion
!> (z = exp(i w dt), the response of each mode U = P / (1 / g_u + c g_v / g_u + wn^2), c its
!> damping per unit modal mass (2 xi wn; a0 for a rigid-body mode),
!> g_v = dt ((1 - gamma) + gamma z) / (z - 1), g_u = (dt g_v + dt^2 ((1/2 - beta) + beta z)) /
!> (z - 1); for average acceleration this is the bilinear transform: the mode sees the
!> forcing at (2 / dt) tan(w dt / 2)). Against the exact response 1 / (wn^2 - w^2 + i c w),
!> summed over the summary's modes with their participation, it gives for each DOF how far
!> the step moves the steady-state amplitude. A friction run is not linear, but it moves
!> between these two systems, and a step that moves both by 20 % cannot give the right
!> answer (a fuzz deck at n1 = 1, 6.4 steps in the table's period: peak displacement 267 %
!> off, no other report). Above harmonic_error_limit the summary says "unresolved" and the
!> executable and the command line warn. The Moreau-Jean technique's theta-method is judged
!> the same way, by its own closed form (theta_response). Not applicable: a record or no
!> table motion (their content is not one frequency), no modes computed (n_modes = 0), or
!> the event-driven technique (no step).
module fd_harmonic_resolution
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fmt_int, allocation_error
   use fd_names, only: technique_step_rule, rule_none, rule_theta, excitation_harmonic
   use fd_matrices, only: modes_type, modes_kept, mode_damping, mode_participation
   use fd_model, only: model_type
   use fd_result, only: result_type, run_setup, setup_of, harmonic_error_limit
   implicit none
   private

   !> harmonic_error_limit: the relative change of a DOF's linear steady-state amplitude above
   !> which the step does not resolve the table's frequency (fd_result's, by which fd_warnings
   !> judges)
   public :: harmonic_resolution, newmark_response, theta_response, harmonic_error_limit

contains

   !> Steady-state response U / P of a mode (unit modal mass, circular frequency wn, damping
   !> c per unit modal mass, 2 xi wn) to a force P exp(i w t) sampled at the steps dt of
   !> Newmark's (beta, gamma). ok = .false. when w dt is a multiple of 2 pi (the steps see a
   !> constant force).
   pure subroutine newmark_response(w, wn, c, dt, beta, gamma, h, ok)
      real(dp), intent(in) :: w, wn         !! forcing and natural circular frequency [rad/s]
      real(dp), intent(in) :: c             !! damping per unit modal mass [1/s]
      real(dp), intent(in) :: dt            !! step [s]
      real(dp), intent(in) :: beta, gamma   !! Newmark's parameters
      complex(dp), intent(out) :: h         !! U / P [s2]
      logical, intent(out) :: ok            !! the steps resolve a frequency at all
      complex(dp) :: z, zm1, gv, gu
      real(dp) :: x

      x = w*dt
      ! z - 1 = 2 i sin(x / 2) exp(i x / 2), without the cancellation of exp(i x) - 1
      zm1 = cmplx(0.0_dp, 2.0_dp*sin(0.5_dp*x), dp)*cmplx(cos(0.5_dp*x), sin(0.5_dp*x), dp)
      ok = abs(zm1) > 1e-12_dp
      h = (0.0_dp, 0.0_dp)
      if (.not. ok) return
      z = zm1 + 1.0_dp
      gv = dt*((1.0_dp - gamma) + gamma*z)/zm1
      gu = (dt*gv + dt*dt*((0.5_dp - beta) + beta*z))/zm1
      h = 1.0_dp/(1.0_dp/gu + c*gv/gu + wn*wn)
   end subroutine newmark_response

   !> The same for the Moreau-Jean technique's theta-method (fd_moreau_jean): over a step
   !> v1 - v = dt (p_theta - c v_theta - wn^2 u_theta), u1 = u + dt v_theta, with
   !> x_theta = (1 - theta) x + theta x1 for v and u and the force interpolated the same way.
   !> With a = (1 - theta) + theta z and g = (z - 1) / (dt a): U / P = 1 / (g^2 + c g + wn^2)
   !> (for theta = 1/2 the bilinear transform, as Newmark's average acceleration).
   pure subroutine theta_response(w, wn, c, dt, theta, h, ok)
      real(dp), intent(in) :: w, wn         !! forcing and natural circular frequency [rad/s]
      real(dp), intent(in) :: c             !! damping per unit modal mass [1/s]
      real(dp), intent(in) :: dt            !! step [s]
      real(dp), intent(in) :: theta         !! the method's theta, 1/2 to 1
      complex(dp), intent(out) :: h         !! U / P [s2]
      logical, intent(out) :: ok            !! the steps resolve a frequency at all
      complex(dp) :: zm1, a, g
      real(dp) :: x

      x = w*dt
      zm1 = cmplx(0.0_dp, 2.0_dp*sin(0.5_dp*x), dp)*cmplx(cos(0.5_dp*x), sin(0.5_dp*x), dp)
      a = 1.0_dp + theta*zm1
      ok = abs(zm1) > 1e-12_dp .and. abs(a) > 1e-12_dp
      h = (0.0_dp, 0.0_dp)
      if (.not. ok) return
      g = zm1/(dt*a)
      h = 1.0_dp/(g*g + c*g + wn*wn)
   end subroutine theta_response

   !> Sets res%harmonic_error (per DOF, the larger over the stuck and the free system of
   !> | |U_step| / |U| - 1 |, for the DOFs whose amplitude |U| is at least 1 % of the largest)
   !> and res%harmonic_checked, from the summary's modes (res%eng), the table's frequency,
   !> the technique's dt1 and Newmark's beta, gamma (the verdict: fd_warnings).
   subroutine harmonic_resolution(model, beta, gamma, theta, res, error)
      type(model_type), intent(in) :: model               !! the model (masses)
      real(dp), intent(in) :: beta, gamma                 !! Newmark's parameters
      real(dp), intent(in) :: theta                       !! Moreau-Jean's theta
      type(result_type), intent(inout) :: res             !! the result of the run
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      complex(dp), allocatable :: ue(:), ud(:)
      integer :: n, stat
      type(run_setup) :: setup
      real(dp) :: dt1
      logical :: any_system

      n = model%n_dof
      res%harmonic_checked = .false.
      res%harmonic_error = 0.0_dp               ! allocated with the summary (init_result)
      setup = setup_of(res)
      dt1 = setup%dt1
      if (technique_step_rule(res%technique) == rule_none) return
      if (res%eng%excitation /= excitation_harmonic) return
      if (dt1 <= 0.0_dp .or. .not. (res%eng%frequency > 0.0_dp)) return
      allocate (ue(n), ud(n), stat=stat)
      call allocation_error(error, stat, "the step check against the table's frequency ("//trim(fmt_int(n))//" DOFs)")
      if (allocated(error)) return
      any_system = .false.
      call one_system(res%eng%stuck)
      call one_system(res%eng%free)
      res%harmonic_checked = any_system

   contains

      subroutine one_system(modes)
         type(modes_type), intent(in) :: modes
         complex(dp) :: hd, he
         real(dp) :: w, wn, gamma_k, big, c
         integer :: k, i
         logical :: ok_k

         if (modes_kept(modes) == 0) return
         any_system = .true.
         w = 2.0_dp*acos(-1.0_dp)*res%eng%frequency
         ue = (0.0_dp, 0.0_dp)
         ud = (0.0_dp, 0.0_dp)
         do k = 1, modes%n
            wn = sqrt(max(modes%omega2(k), 0.0_dp))
            c = mode_damping(modes, k, res%eng%a0)
            gamma_k = mode_participation(modes, k, model%mass(1:n), model%influence)
            if (technique_step_rule(res%technique) == rule_theta) then
               call theta_response(w, wn, c, dt1, theta, hd, ok_k)
            else
               call newmark_response(w, wn, c, dt1, beta, gamma, hd, ok_k)
            end if
            he = cmplx(wn*wn - w*w, c*w, dp)
            if (.not. ok_k .or. he == (0.0_dp, 0.0_dp)) then
               ! the steps see a constant force, or an undamped resonance (no steady state):
               ! no step resolves its amplitude (an error of 1, beyond the limit)
               res%harmonic_error = 1.0_dp
               return
            end if
            ue = ue + (gamma_k/he)*modes%shape(:, k)
            ud = ud + (gamma_k*hd)*modes%shape(:, k)
         end do
         ! not finite (tested without an ordered comparison, which a NaN would trap in the
         ! checked build): the estimate failed, which is not a "resolved"
         if (.not. (all(ieee_is_finite(real(ue))) .and. all(ieee_is_finite(aimag(ue))) .and. &
                    all(ieee_is_finite(real(ud))) .and. all(ieee_is_finite(aimag(ud))))) then
            res%harmonic_error = 1.0_dp
            return
         end if
         big = maxval(abs(ue))
         if (.not. (big > 0.0_dp)) return
         do i = 1, n
            if (abs(ue(i)) >= 0.01_dp*big) &
               res%harmonic_error(i) = max(res%harmonic_error(i), abs(abs(ud(i))/abs(ue(i)) - 1.0_dp))
         end do
      end subroutine one_system
   end subroutine harmonic_resolution

end module fd_harmonic_resolution
