!> The exact event-driven technique (`technique = 'event_driven'`): unregularized Coulomb
!> friction with event-driven stick-slip switching, the paper's group (ii) done exactly.
!>
!> A sticking device is a rigid link (s' = 0) carrying whatever force |F| <= P mu keeps it
!> stuck; a sliding device carries F = P mu sgn(s'). Between events each phase pattern is a
!> linear time-invariant system whose solution is, on every sub-interval, a Taylor
!> polynomial with a remainder bounded below the rounding level (fd_phase_pattern). On
!> each sub-interval:
!>
!> - every event function (a sliding device's sgn s', a sticking device's P mu -+ F) is a
!>   polynomial; the first instant at which one falls below minus its rounding level is
!>   found by isolation (fd_taylor: a lower bound, Descartes' rule, bisection): no sign
!>   change inside the sub-interval can be missed, whatever the sampling step;
!> - the history is sampled at its rows' times, and the exact extrema of every output
!>   quantity (the zeros of its derivative) give the peaks of the summary and the maxima
!>   between the rows (the `peak_*` columns), one-sided values at the events included;
!>   the storeys' drifts and shears are linear combinations of u, v and F, so polynomials
!>   too: their peaks are exact in the same way;
!> - input and viscous work are integrated exactly (products of polynomials), friction
!>   work is P mu |Delta s| over each slide.
!>
!> At an event the phases are decided by the complementarity problems of the instant
!> (fd_phase_decision). Sub-intervals do not depend on the sampling step dt1: the events
!> found are the same for every dt1.
!>
!> A run's control (fd_run_control) applies as for the other techniques: the rows (and their
!> peak_* maxima, of the DOFs and devices kept) go where it says, and the observer is polled
!> after every sub-interval (cancel, progress, a failed history file).
module fd_event_driven
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_real, fmt_int, allocation_error
   use fd_names, only: law_coulomb, law_name, excitation_types, technique_name, technique_event_driven, &
                       technique_newmark, technique_integrates
   use fd_model, only: model_type, integration_type
   use fd_excitation, only: excitation_type, table_motion, segment_end, forcing_form, forcing_unknown
   use fd_matrices, only: structure_matrices
   use fd_kinematics, only: device_relative, device_abs_relative
   use fd_device_state, only: phase_stick
   use fd_result, only: result_type
   use fd_statistics, only: count_event, count_accumulation
   use fd_observer, only: observer_type, observer_init, observe_start, observe_sample, observe_transitions, &
                          observe_end, observe_extrema, observe_extremum, observe_work, &
                          observe_poll, observe_stop_error, observe_storeys, observe_device_motion
   use fd_run_control, only: run_control, stat_cancelled
   use fd_engineering, only: storey_values, engineering_columns
   use fd_taylor, only: poly_value, poly_value_deriv, poly_abs_bound, first_crossing, stationary_points
   use fd_phase_pattern, only: kmax, cache_find, pattern_entry
   use fd_ed_state, only: ed_state, ed_setup, ed_polynomials, iq_u, iq_v, iq_a, iq_s, iq_f
   use fd_phase_decision, only: decide_phases, device_list, rtol_decision
   implicit none
   private

   public :: run_event_driven, event_driven_check
   public :: ed_work, next_row_time, with_context, check_subintervals, unbounded_series, move_to, values_at, &
             update_global, absorb_until, energy   ! the loop's steps, for their unit suite

   integer, parameter :: ring_size = 64          !! events in the accumulation window
   !> Most sub-intervals a run may need (about an hour of integration): a pattern whose
   !> frequencies need more for the rest of the run is an error, not a run without end.
   real(dp), parameter :: max_subintervals = 1.0e9_dp
   real(dp), parameter :: accumulation_span = 1.0e-9_dp !! [s], times max(1, t): the window
   !> Most events (phases changed or not) within one accumulation window: beyond it the
   !> time no longer advances (the same decision again and again), an error, not a run
   !> without end. An accumulation (Zeno) ends after 2 ring_size phase changes at most.
   integer, parameter :: max_burst = 1000

   !> Everything the loop works on.
   type :: ed_work
      type(ed_state) :: st                                !! state at the current instant
      type(observer_type) :: obs                          !! history, energy balance
      real(dp), allocatable :: env(:)                     !! max |quantity| since the last row
      real(dp), allocatable :: yv(:)                      !! quantities at a point
      real(dp), allocatable :: rts(:, :)                  !! stationary points (kmax, nquant)
      integer, allocatable :: nrt(:), ip(:)               !! their number, the next one
      real(dp), allocatable :: uu(:), vv(:), aa(:)        !! a sample's u, v, relative acceleration
      real(dp), allocatable :: ss(:), sd(:), ff(:)        !! a sample's s, s', F
      real(dp), allocatable :: cu(:), cv(:), cf(:)        !! one order's coefficients of u, v, F
      real(dp), allocatable :: mp(:)                      !! mq' p coefficients (0:kmax)
      real(dp), allocatable :: ein(:), evi(:)             !! power coefficients (0:2 kmax)
      real(dp) :: w_fric = 0.0_dp                         !! friction work [J]
      real(dp) :: ring(ring_size) = -huge(1.0_dp)         !! times of the last events
      integer :: ring_pos = 0
      real(dp) :: last_accumulation = -huge(1.0_dp)       !! time of the last accumulation point
      real(dp) :: burst_t0 = -huge(1.0_dp)                !! first event of the current window
      integer :: burst_n = 0                              !! events since burst_t0 within the window
      real(dp) :: t = 0.0_dp                              !! the current instant [s]
      real(dp) :: t_end = 0.0_dp                          !! the end of the run [s]
      real(dp) :: h = 0.0_dp                              !! dt1, the rows' step [s]
      integer :: nrow = 0                                 !! the next history row
      real(dp) :: s_row = 0.0_dp                          !! its time [s]
   end type ed_work

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
         if (technique_integrates(technique_event_driven, model%dev(d)%law)) cycle
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
      type(error_type), allocatable, intent(out) :: error  !! a phase decision failed, not finite, stop
      type(run_control), intent(inout), target, optional :: ctl !! the run's control (fd_run_control)
      type(ed_work) :: w
      integer :: c0, c1, crate, stat, nqt, n, nd

      call system_clock(c0, crate)
      call event_driven_check(model, exc, error)
      if (allocated(error)) return
      ! the storeys' drifts and shears are output quantities after those of the state, and
      ! the base shear always (without storeys it has no history column, but its peak is
      ! in the summary and is found exactly like the others)
      call ed_setup(model, w%st, max(1, engineering_columns(model)), error)
      if (allocated(error)) return
      n = model%n_dof
      nd = model%n_devices
      nqt = w%st%nquant
      allocate (w%env(nqt), w%yv(nqt), w%rts(kmax, nqt), w%nrt(nqt), w%ip(nqt), w%uu(n), w%vv(n), w%aa(n), &
                w%ss(nd), w%sd(nd), w%ff(nd), w%mp(0:kmax), w%ein(0:2*kmax), w%evi(0:2*kmax), w%cu(n), w%cv(n), &
                w%cf(nd), stat=stat)
      call allocation_error(error, stat, "the exact technique's work arrays of "//trim(fmt_int(nqt))// &
                            " output quantities")
      if (allocated(error)) return
      associate (st => w%st, h => w%h, t_end => w%t_end)
         call structure_matrices(model, st%k, st%c, res%exact%setup%period_stuck, res%exact%setup%xi_stuck, error)
         if (allocated(error)) return
         call observer_init(model, exc, opts, res%exact%setup%period_stuck, res, w%obs, error, ctl)
         if (allocated(error)) return
         h = exc%dt_record/opts%n1
         res%exact%setup%dt1 = h
         t_end = w%obs%nsteps*h
         res%exact%ran = .true.
         res%exact%intervals = w%obs%nsteps
         call start_and_advance(w, model, exc, res, error)
         if (allocated(error)) then
            call with_context(w, error)
            return
         end if
         call observe_end(w%obs, res, st%mass, st%k, st%u, st%v, 0.0_dp, w%w_fric, st%fn)
         res%exact%exponentials = st%cache%builds
      end associate
      call system_clock(c1)
      res%run_time = real(c1 - c0, dp)/real(max(crate, 1), dp)
   end subroutine run_event_driven

   !> The run from t = 0 to its end: the initial phases decided, the first row (the state at
   !> t = 0), and the loop over sub-intervals. An error is that of the instant w%t
   !> (run_event_driven says which).
   subroutine start_and_advance(w, model, exc, res, err)
      type(ed_work), intent(inout) :: w
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: err
      logical :: changed

      associate (st => w%st, t => w%t)
         t = 0.0_dp
         call initial_phases(model, st)
         call decide_phases(model, exc, t, st, changed, err)
         if (allocated(err)) return
         call check_subintervals(w, err)
         if (allocated(err)) return
         call observe_start(w%obs, st%mass, st%k, st%u, st%v, 0.0_dp, st%fn)
         ! the first row: the state at t = 0
         call ed_polynomials(model, exc, t, 0.0_dp, st)
         call storey_polynomials(w, res)
         call values_at(st, 0.0_dp, w%yv)
         w%env = abs(w%yv)
         call write_row(w, exc, res, t, 0.0_dp)
         call update_global(w, res, 0.0_dp, t)
         w%nrow = 1
         w%s_row = next_row_time(w, w%nrow)
         call advance_run(w, model, exc, res, err)
      end associate
   end subroutine start_and_advance

   !> The state at t = 0 (u0, v0) and its phases before the decision: a device moving slides
   !> its way, the others are candidates for sticking (decided by the complementarity
   !> problems); no pattern yet.
   pure subroutine initial_phases(model, st)
      type(model_type), intent(in) :: model         !! the model
      type(ed_state), intent(inout) :: st           !! u, v, phase, near, crossed, cur set
      real(dp) :: sv
      integer :: d

      st%u = model%u0
      st%v = model%v0
      do d = 1, st%nd
         st%phase(d) = phase_stick
         st%near(d) = .false.
         st%crossed(d) = .false.
         sv = device_relative(model, d, st%v)
         if (st%active(d) .and. sv /= 0.0_dp) st%phase(d) = int(sign(1.0_dp, sv))
      end do
      st%cur = 0
   end subroutine initial_phases

   !> Time of history row nrow (dt1 step every*nrow, the last row at nsteps).
   real(dp) function next_row_time(w, k) result(tr)
      type(ed_work), intent(in) :: w
      integer, intent(in) :: k
      tr = min(k*w%obs%every, w%obs%nsteps)*w%h
   end function next_row_time

   !> The context of an error of the run, said once: the technique and the instant w%t (the
   !> loop's own messages leave it to this; the phase decision's and a row's non-finite
   !> values start with it, at their own instant); a cancel is left as it is.
   subroutine with_context(w, err)
      type(ed_work), intent(in) :: w
      type(error_type), intent(inout) :: err
      if (err%stat == stat_cancelled) return   ! a cancel says so, as for the other techniques
      if (index(err%message, "event-driven technique at t = ") /= 1) &
         err%message = "event-driven technique at t = "//trim(fmt_real(w%t))//" s: "//err%message
   end subroutine with_context

   !> An error when the current phases' highest frequency needs more than max_subintervals
   !> sub-intervals for the rest of the run (before their polynomials are built: at 1e30
   !> rad/s their Taylor coefficients overflow).
   subroutine check_subintervals(w, err)
      type(ed_work), intent(in) :: w
      type(error_type), allocatable, intent(out) :: err

      associate (delta => w%st%cache%slot(w%st%cur)%delta, t => w%t, t_end => w%t_end)
         if (t_end - t > max_subintervals*delta) then
            call fatal_error(err, "the structure's highest frequency with the current phases "// &
                             "needs sub-intervals of "//trim(fmt_real(delta))// &
                             " s: more than "//trim(fmt_real(max_subintervals))//" for the "// &
                             trim(fmt_real(t_end - t))//" s left; check for a stiff spring on a "// &
                             "small mass (the frequencies sqrt(k/m)), or use the velocity law")
         end if
      end associate
   end subroutine check_subintervals

   !> The error of a sub-interval on which the Taylor series' remainder stays above the
   !> rounding level down to span: no event can be located (the instant is with_context's).
   subroutine unbounded_series(span, err)
      real(dp), intent(in) :: span                  !! the shortest sub-interval tried [s]
      type(error_type), allocatable, intent(out) :: err
      call fatal_error(err, "the Taylor series' remainder stays above the rounding level on sub-intervals down "// &
                       "to "//trim(fmt_real(span))//" s, so events cannot be located; use moreau_jean or the "// &
                       "velocity law")
   end subroutine unbounded_series

   !> The loop over sub-intervals from t = 0 to t_end.
   subroutine advance_run(w, model, exc, res, err)
      type(ed_work), intent(inout) :: w
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: err
      real(dp) :: span, tb, s_use, s_ev, thr, smin, tol, t_new
      integer :: e, kk, halvings
      logical :: fired, found, fresh, stop

      associate (st => w%st, t => w%t, t_end => w%t_end)
         fresh = .true.
         do while (t < t_end)
            tb = segment_end(exc, t, t_end)
            call check_subintervals(w, err)
            if (allocated(err)) return
            span = min(st%cache%slot(st%cur)%delta, tb - t)
            ! the polynomials, with remainders below the rounding level of the state and
            ! of the table acceleration (which alone drives a pattern with no free coordinate)
            do halvings = 0, 40
               call ed_polynomials(model, exc, t, span, st)
               if (st%rem <= 2.0_dp**(-50)*st%size .and. st%grem <= 2.0_dp**(-50)*st%gsize) exit
               span = 0.5_dp*span
            end do
            if (halvings > 40) then   ! no sub-interval bounds the series: no event is certain
               call unbounded_series(span, err)
               return
            end if
            call storey_polynomials(w, res)
            kk = st%order
            smin = 8.0_dp*epsilon(1.0_dp)*(abs(t) + span)
            tol = 2.0_dp*epsilon(1.0_dp)*(abs(t) + span)
            if (fresh) then
               ! after a decision: a value below zero within the decision's tolerance is
               ! accepted; the band starts below it
               do e = 1, 2*st%nd
                  st%offs(e) = 0.0_dp
                  if (st%eon(e)) st%offs(e) = min(0.0_dp, st%ec(0, e))
               end do
               fresh = .false.
            end if
            ! the first crossing of any event function: g <= min(0, offs) - eta
            s_use = span
            fired = .false.
            do e = 1, 2*st%nd
               if (.not. st%eon(e)) cycle
               thr = st%offs(e) - st%eta(e)
               st%pc1(0:kk) = st%ec(0:kk, e)
               st%pc1(0) = st%pc1(0) - thr - st%erem(e)
               if (st%pc1(0) <= 0.0_dp) then
                  s_ev = 0.0_dp
                  found = .true.
               else
                  call first_crossing(st%pc1(0:kk), s_use, smin, tol, st%pw(0:kk, :), st%pw2(0:kk), s_ev, found)
               end if
               if (found .and. s_ev <= s_use) then
                  s_use = s_ev
                  fired = .true.
               end if
            end do
            ! rows, peaks and maxima between rows, energy, friction work over [0, s_use]
            call observe_subinterval(w, exc, res, s_use, err)
            if (allocated(err)) return
            if (fired) then
               t_new = t + s_use
            else if (span == tb - t) then
               t_new = tb
            else
               t_new = t + span
            end if
            call move_to(w, s_use)
            t = t_new
            if (fired) then
               call event_at(w, model, exc, res, err)
               if (allocated(err)) return
               fresh = .true.
            end if
            ! cancel, progress, a failed history file: after every sub-interval
            call observe_poll(w%obs, t, stop)
            if (stop) then
               call observe_stop_error(w%obs, err)
               return
            end if
         end do
      end associate
   end subroutine advance_run

   !> Move the state to s on the current sub-interval.
   subroutine move_to(w, s)
      type(ed_work), intent(inout) :: w
      real(dp), intent(in) :: s
      integer :: i, gi
      associate (st => w%st, pat => w%st%cache%slot(w%st%cur))
         do gi = 1, pat%nq
            st%q(gi) = poly_value(st%qc(gi, 0:st%order), s)
            st%p(gi) = poly_value(st%pc(gi, 0:st%order), s)
         end do
         if (pat%general) then
            st%u = st%uc
            st%v = 0.0_dp
            do gi = 1, pat%nq
               st%u = st%u + pat%tm(:, gi)*st%q(gi)
               st%v = st%v + pat%tm(:, gi)*st%p(gi)
            end do
            return
         end if
         do i = 1, st%n
            gi = pat%grp(i)
            if (gi == 0) then
               st%u(i) = st%uc(i)
               st%v(i) = 0.0_dp
            else
               st%u(i) = st%q(gi) + st%uc(i)
               st%v(i) = st%p(gi)
            end if
         end do
      end associate
   end subroutine move_to

   !> The polynomials of the storeys' drifts and shears (drift1, V1, ..., Vb after the
   !> state's quantities), order by order from those of u, v and F: they are linear in them.
   subroutine storey_polynomials(w, res)
      type(ed_work), intent(inout) :: w
      type(result_type), intent(in) :: res
      integer :: m, nb, ns, n1
      associate (st => w%st)
         nb = st%nbase
         ns = res%eng%n_storeys
         if (st%nquant == nb) return
         n1 = 3*st%n
         do m = 0, st%order
            w%cu = st%yc(m, 1:n1:3)
            w%cv = st%yc(m, 2:n1:3)
            w%cf = st%yc(m, n1 + 2:n1 + 2*st%nd:2)
            call storey_values(res%eng, w%cu, w%cv, w%cf, st%yc(m, nb + 1:nb + 2*ns - 1:2), &
                               st%yc(m, nb + 2:nb + 2*ns:2), st%yc(m, nb + 2*ns + 1))
         end do
      end associate
   end subroutine storey_polynomials

   !> Values of every quantity at s on the current sub-interval.
   subroutine values_at(st, s, y)
      type(ed_state), intent(in) :: st
      real(dp), intent(in) :: s
      real(dp), intent(out) :: y(:)
      integer :: iq
      do iq = 1, st%nquant
         y(iq) = poly_value(st%yc(0:st%order, iq), s)
      end do
   end subroutine values_at

   !> The history row at time tr (s on the current sub-interval), with the maxima since
   !> the last row.
   subroutine write_row(w, exc, res, tr, s)
      type(ed_work), intent(inout) :: w
      type(excitation_type), intent(in) :: exc
      type(result_type), intent(inout) :: res
      real(dp), intent(in) :: tr, s
      real(dp) :: xg, vg, ag, dv
      integer :: i, dd
      associate (st => w%st)
         call table_motion(exc, tr, xg, vg, ag)
         do i = 1, st%n
            w%uu(i) = w%yv(iq_u(i))
            w%vv(i) = w%yv(iq_v(i))
            w%aa(i) = w%yv(iq_a(i)) - st%rinf(i)*ag
         end do
         do dd = 1, st%nd
            w%ss(dd) = w%yv(iq_s(st%n, dd))
            call poly_value_deriv(st%yc(0:st%order, iq_s(st%n, dd)), s, xg, dv)
            w%sd(dd) = dv
            w%ff(dd) = w%yv(iq_f(st%n, dd))
         end do
         ! the maxima of the history's columns (without storeys, not the base shear's)
         call observe_sample(w%obs, res, tr, ag, w%uu, w%vv, w%aa, w%ss, w%sd, w%ff, st%phase, &
                             w%env(1:merge(st%nquant, st%nbase, res%eng%n_storeys > 0)))
         ! the storeys at the row: the values kept as residual ones at the last
         call observe_storeys(res, tr, w%uu, w%vv, w%ss, w%ff)
      end associate
   end subroutine write_row

   !> Peaks of the summary from the values yv at time tp.
   subroutine update_global(w, res, s, tp)
      type(ed_work), intent(in) :: w
      type(result_type), intent(inout) :: res
      real(dp), intent(in) :: s, tp
      if (s < 0.0_dp) return
      call observe_extrema(res, w%yv(1:w%st%nquant), tp)
   end subroutine update_global

   !> Over [0, s_use] of the current sub-interval: the rows that fall in it, the exact
   !> extrema (summary peaks, maxima between rows), the input and viscous work, and the
   !> friction work.
   subroutine observe_subinterval(w, exc, res, s_use, err)
      type(ed_work), intent(inout) :: w
      type(excitation_type), intent(in) :: exc
      type(result_type), intent(inout) :: res
      real(dp), intent(in) :: s_use
      type(error_type), allocatable, intent(out) :: err
      real(dp) :: smin, tol, x, y, sr
      integer :: iq, kk, j
      associate (st => w%st, t => w%t, nrow => w%nrow, s_row => w%s_row)
         kk = st%order
         smin = 8.0_dp*epsilon(1.0_dp)*(abs(t) + s_use)
         tol = 2.0_dp*epsilon(1.0_dp)*(abs(t) + s_use)
         ! the one-sided values at the start (after an event: the right limits)
         call values_at(st, 0.0_dp, w%yv)
         do iq = 1, st%nquant
            w%env(iq) = max(w%env(iq), abs(w%yv(iq)))
         end do
         call update_global(w, res, 0.0_dp, t)
         ! stationary points of every quantity in (0, s_use)
         do iq = 1, st%nquant
            w%nrt(iq) = 0
            w%ip(iq) = 1
            if (s_use > 0.0_dp) &
               call stationary_points(st%yc(0:kk, iq), s_use, smin, tol, st%pw(0:kk, :), st%pw2(0:kk), &
                                      w%rts(:, iq), w%nrt(iq))
         end do
         ! rows inside (0, s_use], each with the maxima since the previous row
         do while (nrow <= res%nout .and. s_row - t <= s_use)
            sr = max(0.0_dp, s_row - t)
            call absorb_until(w, res, sr)
            call values_at(st, sr, w%yv)
            if (.not. all(ieee_is_finite(w%yv))) then
               call fatal_error(err, "event-driven technique at t = "//trim(fmt_real(s_row))// &
                                " s: the solution is not finite (an overflow); check the masses, the "// &
                                "stiffnesses, the initial displacements u0 and velocities v0, and the table motion")
               return
            end if
            do iq = 1, st%nquant
               w%env(iq) = max(w%env(iq), abs(w%yv(iq)))
            end do
            call write_row(w, exc, res, s_row, sr)
            w%env = abs(w%yv)
            nrow = nrow + 1
            s_row = next_row_time(w, nrow)
         end do
         call absorb_until(w, res, s_use)
         ! the end point (before an event: the left limits)
         call values_at(st, s_use, w%yv)
         do iq = 1, st%nquant
            w%env(iq) = max(w%env(iq), abs(w%yv(iq)))
         end do
         call update_global(w, res, s_use, t + s_use)
         call energy(w, res, s_use)
         ! friction work: P mu |Delta s| over the slide, in all and per device
         do j = 1, st%nd
            if (.not. st%active(j) .or. st%phase(j) == phase_stick) cycle
            x = poly_value(st%yc(0:kk, iq_s(st%n, j)), s_use)
            y = st%yc(0, iq_s(st%n, j))
            w%w_fric = w%w_fric + st%slip(j)*abs(x - y)
            call observe_device_motion(w%obs, j, st%slip(j)*abs(x - y), abs(x - y))
         end do
      end associate
   end subroutine observe_subinterval

   !> Take the stationary points up to s into the maxima (envelope and summary).
   subroutine absorb_until(w, res, s)
      type(ed_work), intent(inout) :: w
      type(result_type), intent(inout) :: res
      real(dp), intent(in) :: s
      integer :: iq, kk
      real(dp) :: x, y
      kk = w%st%order
      do iq = 1, w%st%nquant
         do while (w%ip(iq) <= w%nrt(iq))
            x = w%rts(w%ip(iq), iq)
            if (x > s) exit
            y = abs(poly_value(w%st%yc(0:kk, iq), x))
            w%env(iq) = max(w%env(iq), y)
            call observe_extremum(res, iq, y, w%t + x)
            w%ip(iq) = w%ip(iq) + 1
         end do
      end do
   end subroutine absorb_until

   !> Input work -int ag mq'p and viscous work int p'Cq p over [0, s], exactly (the
   !> polynomials' products integrated term by term).
   subroutine energy(w, res, s)
      type(ed_work), intent(inout) :: w
      type(result_type), intent(inout) :: res
      real(dp), intent(in) :: s
      integer :: j, m, kk, gi
      real(dp) :: ein, evi, sp
      associate (st => w%st, pat => w%st%cache%slot(w%st%cur))
         if (pat%nq == 0 .or. s <= 0.0_dp) return
         kk = st%order
         do m = 0, kk
            w%mp(m) = 0.0_dp
            do gi = 1, pat%nq
               w%mp(m) = w%mp(m) + pat%mq(gi)*pat%lq(gi)*st%pc(gi, m)
            end do
         end do
         w%ein(0:2*kk) = 0.0_dp
         w%evi(0:2*kk) = 0.0_dp
         ! p_j' Cq p_m = p_m' Cq p_j: the terms m > j count twice
         do m = 0, kk
            do j = 0, kk
               w%ein(j + m) = w%ein(j + m) + st%g(j)*w%mp(m)
            end do
            sp = 0.0_dp
            do gi = 1, pat%nq
               sp = sp + st%pc(gi, m)*st%cp(gi, m)
            end do
            w%evi(2*m) = w%evi(2*m) + sp
            do j = 0, m - 1
               sp = 0.0_dp
               do gi = 1, pat%nq
                  sp = sp + st%pc(gi, j)*st%cp(gi, m)
               end do
               w%evi(j + m) = w%evi(j + m) + 2.0_dp*sp
            end do
         end do
         ein = 0.0_dp
         evi = 0.0_dp
         do m = 2*kk, 0, -1
            ein = ein*s + w%ein(m)/(m + 1)
            evi = evi*s + w%evi(m)/(m + 1)
         end do
         call observe_work(res, -ein*s, evi*s)
      end associate
   end subroutine energy

   !> An event at t: which devices are at it, the decision, and the accumulation guard.
   subroutine event_at(w, model, exc, res, err)
      type(ed_work), intent(inout) :: w
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: err
      integer :: dd, e, oldest
      real(dp) :: x, vs, thr
      logical :: chg
      associate (st => w%st, t => w%t)
         ! the polynomials at the event instant (the old pattern, span 0): crossed
         ! functions and sliders at zero velocity
         call ed_polynomials(model, exc, t, 0.0_dp, st)
         do dd = 1, st%nd
            st%crossed(dd) = .false.
            st%near(dd) = .false.
            do e = 2*dd - 1, 2*dd
               if (.not. st%eon(e)) cycle
               thr = st%offs(e) - st%eta(e)
               if (st%ec(0, e) - st%erem(e) <= thr) st%crossed(dd) = .true.
            end do
            if (st%active(dd) .and. st%phase(dd) /= phase_stick) then
               x = device_relative(model, dd, st%v)
               vs = device_abs_relative(model, dd, st%v)
               st%near(dd) = st%crossed(dd) .or. abs(x) <= max(rtol_decision*vs, 4.0_dp*st%eta(2*dd - 1))
            end if
         end do
         call decide_phases(model, exc, t, st, chg, err)
         if (allocated(err)) return
         ! no event loop without end: at most max_burst events within one window
         if (t - w%burst_t0 <= accumulation_span*max(1.0_dp, abs(t))) then
            w%burst_n = w%burst_n + 1
            if (w%burst_n >= max_burst) then
               call stalled_events(w, err)
               return
            end if
         else
            w%burst_t0 = t
            w%burst_n = 1
         end if
         if (.not. chg) return
         call observe_transitions(res, st%oldph, st%phase)
         call count_event(res%exact, t)
         ! accumulation guard: ring_size phase changes within the window
         w%ring_pos = mod(w%ring_pos, ring_size) + 1
         w%ring(w%ring_pos) = t
         oldest = mod(w%ring_pos, ring_size) + 1
         if (t - w%ring(oldest) <= accumulation_span*max(1.0_dp, abs(t))) then
            if (t - w%last_accumulation <= accumulation_span*max(1.0_dp, abs(t))) then
               call fatal_error(err, "events accumulate again where sticking at the limit of the sequence should have "// &
                                "ended them; try technique = 'newmark' with law = 'velocity', or report the deck")
               return
            end if
            w%last_accumulation = t
            call accumulation(w, model, exc, res, err)
            if (allocated(err)) return
            w%ring = -huge(1.0_dp)
         end if
      end associate
   end subroutine event_at

   !> The error of max_burst events within one window: the time does not advance.
   subroutine stalled_events(w, err)
      type(ed_work), intent(inout) :: w
      type(error_type), allocatable, intent(out) :: err
      integer :: dd, m
      character(len=:), allocatable :: list
      associate (st => w%st, t => w%t)
         m = 0
         do dd = 1, st%nd
            if (.not. (st%crossed(dd) .or. st%near(dd))) cycle
            m = m + 1
            st%cand(m) = dd
         end do
         if (m > 0) then
            call device_list(st%cand, m, list)
            list = ", last at "//list
         else
            list = ""
         end if
         call fatal_error(err, trim(fmt_int(max_burst))//" events within "// &
                          trim(fmt_real(t - w%burst_t0))//" s"//list//", the same instant decided again "// &
                          "and again (the time does not advance); try technique = 'moreau_jean', or "// &
                          "technique = 'newmark' with law = 'velocity', or report the deck")
      end associate
   end subroutine stalled_events

   !> An accumulation of events (a Zeno sequence) at t: the devices at zero relative
   !> velocity stick at the limit of the sequence, provided their forces hold.
   subroutine accumulation(w, model, exc, res, err)
      type(ed_work), intent(inout) :: w
      type(model_type), intent(in) :: model
      type(excitation_type), intent(in) :: exc
      type(result_type), intent(inout) :: res
      type(error_type), allocatable, intent(out) :: err
      integer :: dd, r, nbad
      real(dp) :: x, vs, xg, vg, ag, f
      character(len=:), allocatable :: list
      associate (st => w%st, t => w%t)
         st%oldph = st%phase
         st%newph = st%phase
         do dd = 1, st%nd
            if (.not. st%active(dd) .or. st%phase(dd) == phase_stick) cycle
            x = device_relative(model, dd, st%v)
            vs = device_abs_relative(model, dd, st%v)
            if (abs(x) <= 1.0e-9_dp*max(vs, tiny(1.0_dp))) st%newph(dd) = phase_stick
         end do
         call cache_find(st%cache, model, st%mass, st%k, st%c, st%active, st%newph, st%slip, exc, [st%cur], &
                         st%cur, err)
         if (allocated(err)) return
         call pattern_entry(st%cache%slot(st%cur), model, st%mass, st%k, st%newph, st%slip, st%u, st%v, &
                            st%q, st%p, st%uc, st%b1, st%f0, st%fn)
         st%phase = st%newph
         call table_motion(exc, t, xg, vg, ag)
         nbad = 0
         associate (pat => st%cache%slot(st%cur))
            do r = 1, pat%ns
               f = pat%fag(r)*ag + st%f0(r) + sum(pat%fq(r, 1:pat%nq)*st%q(1:pat%nq)) + &
                   sum(pat%fp(r, 1:pat%nq)*st%p(1:pat%nq))
               if (abs(f) > st%slip(pat%ids(r))*(1.0_dp + 1.0e-6_dp)) then
                  nbad = nbad + 1
                  st%cand(nbad) = pat%ids(r)
               end if
            end do
         end associate
         if (nbad > 0) then
            call device_list(st%cand, nbad, list)
            call fatal_error(err, trim(fmt_int(ring_size))//" phase changes within "// &
                             trim(fmt_real(accumulation_span*max(1.0_dp, abs(t))))//" s, and sticking at their "// &
                             "limit would need forces above P mu in "//list//"; try technique = "// &
                             "'newmark' with law = 'velocity', or report the deck")
            return
         end if
         call observe_transitions(res, st%oldph, st%phase)
         call count_accumulation(res%exact, t)
      end associate
   end subroutine accumulation

end module fd_event_driven
