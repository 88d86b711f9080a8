!> The exact event-driven technique (`technique = 'event_driven'`): unregularized Coulomb
!> friction with event-driven stick-slip switching, the paper's group (ii) done exactly.
!>
!> A sticking device is a rigid link (s' = 0) carrying whatever force |F| <= P mu keeps it
!> stuck; a sliding device carries F = P mu sgn(s'). Between events each phase pattern is a
!> linear time-invariant system integrated exactly (fd_phase_pattern). The loop steps by
!> dt1 = dt_record / n1 (the sampling grid); in each step the event functions
!> (fd_phase_decision) are evaluated on the exact solution, the first zero of one that has
!> become <= 0 is located to round-off by Brent's method (fd_root_finder), the state is
!> advanced there and the phases are decided again. Input and viscous work are integrated
!> by 3-point Gauss-Legendre on the exact state; friction work is exact.
module fd_event_driven
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_real, fmt_int
   use fd_names, only: law_coulomb, law_name, excitation_types, technique_name, technique_event_driven, &
                       technique_newmark
   use fd_model, only: model_type, integration_type
   use fd_excitation, only: excitation_type, table_motion, segment_end, forcing_form, forcing_unknown
   use fd_matrices, only: structure_matrices
   use fd_kinematics, only: device_kinematics, device_relative
   use fd_linalg, only: sym_matvec
   use fd_device_state, only: phase_stick
   use fd_result, only: result_type
   use fd_observer, only: observer_type, observer_init, sample_due, observe_start, observe_peaks, &
                          observe_sample, observe_transitions, observe_end, observe_poll, observe_stop_error
   use fd_run_control, only: run_control
   use fd_root_finder, only: root_function, brent_root
   use fd_phase_pattern, only: forcing_changed, propagate, pattern_exp, quad_x, quad_w
   use fd_ed_state, only: ed_state, ed_setup, set_pattern, expand_state, step_propagators
   use fd_phase_decision, only: decide_phases, stuck_forces, event_values
   implicit none
   private

   public :: run_event_driven, event_driven_check

   !> Everything the loop works on.
   type :: ed_work
      type(ed_state) :: st                                !! state at the current instant
      type(observer_type) :: obs                          !! peaks, history, energy balance
      real(dp), allocatable :: g_end(:), g_try(:), s0(:)  !! event values, start positions (nd)
      real(dp), allocatable :: s(:), sd(:)                !! device kinematics (nd)
      integer, allocatable :: old(:)                      !! phases before an event (nd)
      real(dp), allocatable :: rn(:), vv(:)               !! work (n)
      real(dp) :: w_fric = 0.0_dp                         !! friction work [J]
      integer :: n_events = 0                             !! events located
   end type ed_work

   !> Event function g_d(tau) of one device over a step from tc, on the exact solution:
   !> the object Brent's method evaluates.
   type, extends(root_function) :: event_function
      type(model_type), pointer :: model => null()        !! the model
      type(excitation_type), pointer :: exc => null()     !! the table motion
      type(ed_work), pointer :: w => null()               !! the loop's state
      integer :: device = 0                               !! d
      real(dp) :: tc = 0.0_dp                             !! start of the step [s]
      real(dp) :: h = 0.0_dp                              !! the full step [s]
   contains
      procedure :: evaluate => event_at
   end type event_function

contains

   !> What the exact technique cannot integrate: a device whose law is not 'coulomb', a
   !> table motion with no exact form. Messages name the group, the variable, the value and
   !> what to set.
   subroutine event_driven_check(model, exc, error)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      type(error_type), allocatable, intent(out) :: error !! what cannot be integrated
      character(len=:), allocatable :: idx, tech, name
      integer :: d

      tech = "technique = '"//trim(technique_name(technique_event_driven))//"'"
      do d = 1, model%n_devices
         if (model%dev(d)%law == law_coulomb) cycle
         idx = 'law('//trim(fmt_int(d))//')'
         call fatal_error(error, "group &friction: "//idx//" = '"//trim(law_name(model%dev(d)%law))// &
                          "' is invalid with "//tech//" of &integration: the exact event-driven technique "// &
                          "integrates 'coulomb' devices only; set "//idx//" = '"//trim(law_name(law_coulomb))// &
                          "', or technique = '"//trim(technique_name(technique_newmark))// &
                          "' with a regularized law for every device")
         return
      end do
      if (forcing_form(exc) == forcing_unknown) then
         name = 'unknown'
         if (exc%kind >= 1 .and. exc%kind <= size(excitation_types)) name = trim(excitation_types(exc%kind)%name)
         call fatal_error(error, "group &excitation: excitation_type = '"//name//"' is invalid with "//tech// &
                          " of &integration: the exact technique has no exact form of this table motion; set "// &
                          "technique = '"//trim(technique_name(technique_newmark))//"'")
      end if
   end subroutine event_driven_check

   !> Integrate a model whose devices all follow the exact Coulomb law.
   subroutine run_event_driven(model, exc, opts, res, error, ctl)
      type(model_type), intent(in), target :: model        !! validated model (all devices coulomb)
      type(excitation_type), intent(in), target :: exc     !! table motion
      type(integration_type), intent(in) :: opts           !! n1 and output_every are used
      type(result_type), intent(out) :: res                !! histories and summary
      type(error_type), allocatable, intent(out) :: error  !! event chattering, singular phase, stop
      type(run_control), intent(inout), target, optional :: ctl !! the run's control (fd_run_control)
      type(ed_work), target :: w
      real(dp) :: h, t, tn, tb, xg, vg, ag
      integer :: k, c0, c1, crate, stat
      logical :: stop

      call system_clock(c0, crate)
      call event_driven_check(model, exc, error)
      if (allocated(error)) return
      call ed_setup(model, w%st, stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the matrices of n_dof = "//trim(fmt_int(model%n_dof))//" DOFs")
         return
      end if
      associate (st => w%st)
         allocate (w%g_end(st%nd), w%g_try(st%nd), w%s0(st%nd), w%s(st%nd), w%sd(st%nd), w%old(st%nd))
         allocate (w%rn(st%n), w%vv(st%n))
         call structure_matrices(model, st%k, st%c, res%period_stuck, res%xi_stuck, error)
         if (allocated(error)) return
         call observer_init(model, exc, opts, res, w%obs, error, ctl)
         if (allocated(error)) return
         h = exc%dt_record/opts%n1
         res%dt1 = h
         res%dt2 = 0.0_dp
         res%dt_min = 0.0_dp

         st%u = model%u0
         st%v = model%v0
         t = 0.0_dp
         st%phase = 0
         do k = 1, st%nd
            if (st%active(k) .and. abs(device_relative(model, k, st%v)) > 0.0_dp) &
               st%phase(k) = int(sign(1.0_dp, device_relative(model, k, st%v)))
            if (.not. st%active(k)) st%phase(k) = 0
         end do
         call decide_phases(model, exc, t, st, error)
         if (allocated(error)) return
         call observe_start(w%obs, st%mass, st%k, st%u, st%v, 0.0_dp, w%rn)
         call table_motion(exc, t, xg, vg, ag)
         call device_kinematics(model, st%u, st%v, w%s, w%sd)
         call observe_sample(w%obs, res, t, ag, st%u, st%v, st%acc, w%s, w%sd, st%force, st%phase)

         do k = 1, w%obs%nsteps
            tn = k*h
            ! step to tn, stopping at a change of the form of the forcing (end of the ramp)
            do
               tb = segment_end(exc, t, tn)
               call advance(model, exc, t, tb, h, w, res, error)
               if (allocated(error)) return
               t = tb
               if (forcing_changed(st%pat, exc, t)) then
                  call set_pattern(model, exc, t, st, error)   ! the ramp ended: steady forcing
                  if (allocated(error)) return
               end if
               if (tb >= tn) exit
            end do
            t = tn
            res%steps_dt1 = res%steps_dt1 + 1
            call table_motion(exc, t, xg, vg, ag)
            call device_kinematics(model, st%u, st%v, w%s, w%sd)
            call observe_peaks(res, t, st%u, st%v, st%acc, ag, w%s, st%force)
            if (sample_due(w%obs, k)) then
               if (.not. all(ieee_is_finite(st%u))) then
                  call fatal_error(error, "event-driven technique: the solution is not finite at t = "// &
                                   trim(fmt_real(t))//" s")
                  return
               end if
               call observe_sample(w%obs, res, t, ag, st%u, st%v, st%acc, w%s, w%sd, st%force, st%phase)
            end if
            call observe_poll(w%obs, t, stop)
            if (stop) then
               call observe_stop_error(w%obs, error)
               return
            end if
         end do
         call observe_end(w%obs, res, st%mass, st%k, st%u, st%v, 0.0_dp, w%w_fric, w%rn)
         res%factorizations = st%n_expm
         res%events = w%n_events
      end associate
      call system_clock(c1)
      res%run_time = real(c1 - c0, dp)/real(max(crate, 1), dp)
   end subroutine run_event_driven

   !> Advance from t to tb (<= one step h), locating and handling every event on the way.
   subroutine advance(model, exc, t, tb, h, w, res, error)
      type(model_type), intent(in), target :: model        !! the model
      type(excitation_type), intent(in), target :: exc     !! the table motion
      real(dp), intent(in) :: t                            !! start [s]
      real(dp), intent(in) :: tb                           !! end [s]
      real(dp), intent(in) :: h                            !! the full step [s]
      type(ed_work), intent(inout), target :: w            !! the loop's state
      type(result_type), intent(inout) :: res              !! transitions, energy
      type(error_type), allocatable, intent(out) :: error  !! failed exponential or solve,
                                                           !! chattering
      type(event_function) :: ev
      real(dp) :: tc, tau, tau_ev
      integer :: d, stalls
      logical :: fired

      ev%model => model
      ev%exc => exc
      ev%w => w
      ev%h = h
      tc = t
      stalls = 0
      associate (st => w%st)
         do
            if (tc >= tb) exit
            tau = tb - tc
            ! a full step (tb - tc differs from h by the rounding of k h): use the kept propagators
            if (abs(tau - h) <= 1.0e-9_dp*h) tau = h
            call step_propagators(st, tau, h, error)
            if (allocated(error)) return
            call state_at(model, exc, tc, tau, st, w%g_end, error)
            if (allocated(error)) return
            ! which events fire in (tc, tc + tau]? g_d(0) >= 0 (holding, or sliding on)
            fired = .false.
            tau_ev = tau
            ev%tc = tc
            do d = 1, st%nd
               if (w%g_end(d) > 0.0_dp) cycle
               if (st%phase(d) /= phase_stick .and. st%fresh(d) .and. w%g_end(d) == 0.0_dp) cycle
               fired = .true.
               ev%device = d
               call brent_root(ev, 0.0_dp, 1.0_dp, tau, w%g_end(d), tau_ev, error, origin=tc)
               if (allocated(error)) return
               tau = min(tau, tau_ev)
            end do
            ! integrate energy over [tc, tc + tau] and move there
            call energy(exc, tc, tau, h, w, res, error)
            if (allocated(error)) return
            if (st%pat%m > 0) then
               ! the root finder leaves the propagators of its last trial: those over tau
               ! again unless they are the kept ones of the full step or of the whole interval
               if ((tau /= tb - tc .and. tau /= h) .or. st%tau_ph /= tau) then
                  call step_propagators(st, tau, h, error)
                  if (allocated(error)) return
               end if
               call propagate(exc, st%pat, tc, tau, st%x, st%ph, st%q1, st%q2, st%y, st%wk)
               st%x = st%y
            end if
            do d = 1, st%nd
               w%s0(d) = device_relative(model, d, st%u)
            end do
            call expand_state(exc, tc + tau, st)
            do d = 1, st%nd
               if (st%active(d) .and. st%phase(d) /= phase_stick) &
                  w%w_fric = w%w_fric + st%slip(d)*abs(device_relative(model, d, st%u) - w%s0(d))
            end do
            if (fired) then
               tc = tc + tau
            else
               tc = tb   ! the whole remaining interval (tau may be snapped to h)
            end if
            if (fired) then
               if (tau <= 1.0e-13_dp*max(1.0_dp, tc)) then
                  stalls = stalls + 1
                  if (stalls > 50) then
                     call fatal_error(error, "event-driven technique: events accumulate at t = "// &
                                      trim(fmt_real(tc))//" s (stick-slip chattering)")
                     return
                  end if
               else
                  stalls = 0
               end if
               w%n_events = w%n_events + 1
               w%old = st%phase
               call decide_phases(model, exc, tc, st, error)
               if (allocated(error)) return
               call observe_transitions(res, w%old, st%phase)
            else
               st%fresh = .false.
               call stuck_forces(model, exc, tc, st, error)
               if (allocated(error)) return
            end if
         end do
      end associate
   end subroutine advance

   !> Event values gv at tc + tt (ph, q1, q2 must be the propagators over tt); the state
   !> is left expanded at tc.
   subroutine state_at(model, exc, tc, tt, st, gv, error)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      real(dp), intent(in) :: tc                    !! start of the step [s]
      real(dp), intent(in) :: tt                    !! time into the step [s]
      type(ed_state), intent(inout) :: st           !! the state
      real(dp), intent(out) :: gv(:)                !! event values
      type(error_type), allocatable, intent(out) :: error !! failed least-squares solve

      if (st%pat%m > 0) then
         call propagate(exc, st%pat, tc, tt, st%x, st%ph, st%q1, st%q2, st%y, st%wk)
         call expand_state(exc, tc + tt, st, trial=.true.)
      else
         call expand_state(exc, tc + tt, st)
      end if
      call stuck_forces(model, exc, tc + tt, st, error)
      if (allocated(error)) return
      call event_values(model, st, gv)
      ! back to the state at tc (expand overwrote u, v, acc)
      call expand_state(exc, tc, st)
   end subroutine state_at

   !> g_d at tc + x on the exact solution (one matrix exponential, unless x = h).
   subroutine event_at(self, x, fx, error)
      class(event_function), intent(inout) :: self         !! the event function
      real(dp), intent(in) :: x                            !! time into the step [s]
      real(dp), intent(out) :: fx                          !! g_d
      type(error_type), allocatable, intent(out) :: error  !! failed exponential or solve

      fx = 0.0_dp
      call step_propagators(self%w%st, x, self%h, error)
      if (allocated(error)) return
      call state_at(self%model, self%exc, self%tc, x, self%w%st, self%w%g_try, error)
      if (allocated(error)) return
      fx = self%w%g_try(self%device)
   end subroutine event_at

   !> Input and viscous work over [tc, tc + tt] by 3-point Gauss-Legendre on the exact state.
   subroutine energy(exc, tc, tt, h, w, res, error)
      type(excitation_type), intent(in) :: exc      !! the table motion
      real(dp), intent(in) :: tc                    !! start [s]
      real(dp), intent(in) :: tt                    !! length [s]
      real(dp), intent(in) :: h                     !! the full step [s]
      type(ed_work), intent(inout) :: w             !! the loop's state
      type(result_type), intent(inout) :: res       !! e_input and e_viscous accumulated
      type(error_type), allocatable, intent(out) :: error !! failed exponential
      real(dp) :: xg, vg, ag
      integer :: ig, i

      if (tt <= 0.0_dp) return
      associate (st => w%st, pat => w%st%pat)
         do ig = 1, 3
            if (pat%m > 0) then
               if (tt == h .and. pat%h == h) then
                  call propagate(exc, pat, tc, quad_x(ig)*tt, st%x, pat%gphi(:, :, ig), pat%gg1(:, :, ig), &
                                 pat%gg2(:, :, ig), st%y2, st%wk)
               else
                  call pattern_exp(pat, quad_x(ig)*tt, st%pg, st%pq1, st%pq2, st%n_expm, error)
                  if (allocated(error)) return
                  call propagate(exc, pat, tc, quad_x(ig)*tt, st%x, st%pg, st%pq1, st%pq2, st%y2, st%wk)
               end if
               do i = 1, st%n
                  if (pat%grp(i) == 0) then
                     w%vv(i) = 0.0_dp
                  else
                     w%vv(i) = st%y2(pat%nq + pat%grp(i))
                  end if
               end do
            else
               w%vv = 0.0_dp
            end if
            call table_motion(exc, tc + quad_x(ig)*tt, xg, vg, ag)
            res%e_input = res%e_input - quad_w(ig)*tt*ag*sum(st%mass*w%vv)
            call sym_matvec(st%c, w%vv, w%rn, 1.0_dp, 0.0_dp)
            res%e_viscous = res%e_viscous + quad_w(ig)*tt*dot_product(w%vv, w%rn)
         end do
      end associate
   end subroutine energy

end module fd_event_driven
