!> Unit tests of the exact technique's loop helpers (fd_event_driven), each against a
!> contract stated exactly: a free oscillator's state moved along one sub-interval against
!> its closed form; the work integrated over a sub-interval of a damped oscillator on a
!> moving table against the change of its mechanical energy; the row times; the routing of
!> each output quantity to its summary peak; the stationary points taken into the maxima up
!> to a given point only; the error context and the sub-interval budget; and, through the
!> whole loop, the event of a sliding block that stops, at its closed-form instant.
module test_fd_event_driven
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type, fmt_real, fatal_error
   use fd_model, only: model_type, device_type, integration_type, law_coulomb
   use fd_excitation, only: excitation_type, excitation_harmonic
   use fd_result, only: result_type
   use fd_run_control, only: stat_cancelled
   use fd_ed_state, only: ed_setup, ed_polynomials, iq_u, iq_v, iq_a
   use fd_phase_decision, only: decide_phases
   use fd_event_driven, only: run_event_driven, ed_work, next_row_time, with_context, check_subintervals, move_to, values_at, &
                              update_global, absorb_until, energy, unbounded_series
   use test_fd_helpers, only: check_close, pairs_of
   implicit none
   private

   public :: collect_event_driven

   real(dp), parameter :: pi = acos(-1.0_dp)
   real(dp), parameter :: m = 3.0_dp            !! the oscillator's mass [kg]
   real(dp), parameter :: k = 1200.0_dp         !! its spring [N/m] (omega = 20 rad/s)
   real(dp), parameter :: u0 = 0.02_dp          !! initial displacement [m]
   real(dp), parameter :: v0 = -0.15_dp         !! initial velocity [m/s]

contains

   subroutine collect_event_driven(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("a free oscillator moved along a sub-interval: closed form", test_free_oscillator), &
                  new_unittest("work over a sub-interval equals the energy change", test_energy_balance), &
                  new_unittest("rows every output_every steps, the last at nsteps", test_row_times), &
                  new_unittest("summary peaks from values at a point", test_update_global), &
                  new_unittest("stationary points are taken up to s only", test_absorb_until), &
                  new_unittest("an error says the technique and t once", test_with_context), &
                  new_unittest("the unbounded series' error in context says t once", test_unbounded_series), &
                  new_unittest("more than 1e9 sub-intervals left is an error", test_subinterval_budget), &
                  new_unittest("a sliding block stops at m v0 / (P mu)", test_event_location) &
                  ]
   end subroutine collect_event_driven

   !> A single-DOF oscillator (mass m, spring k to the ground, viscous c, no device) on a
   !> table moving harmonically with amplitude amp, at u0, v0 at t = 0, its phases decided
   !> and its polynomials built on the pattern's sub-interval (halved until the remainder
   !> is below the rounding level, as the loop does).
   subroutine oscillator(c, amp, w, model, exc, error)
      real(dp), intent(in) :: c, amp
      type(ed_work), intent(out) :: w
      type(model_type), intent(out) :: model
      type(excitation_type), intent(out) :: exc
      type(error_type), allocatable, intent(out) :: error
      type(fd_error_type), allocatable :: err
      real(dp) :: span
      integer :: halvings
      logical :: changed

      model%n_dof = 1
      model%mass = [m]
      model%u0 = [u0]
      model%v0 = [v0]
      model%n_devices = 0
      allocate (model%dev(0))
      call pairs_of(model)
      exc%kind = excitation_harmonic
      exc%amplitude = amp
      exc%frequency = 1.5_dp
      call ed_setup(model, w%st, 0, err)
      if (.not. allocated(err)) then
         w%st%k = k
         w%st%c = c
         w%st%u = u0
         w%st%v = v0
         w%st%cur = 0
         call decide_phases(model, exc, 0.0_dp, w%st, changed, err)
      end if
      if (allocated(err)) then
         call test_failed(error, err%message)
         return
      end if
      span = w%st%cache%slot(w%st%cur)%delta
      do halvings = 0, 40
         call ed_polynomials(model, exc, 0.0_dp, span, w%st)
         if (w%st%rem <= 2.0_dp**(-50)*w%st%size .and. w%st%grem <= 2.0_dp**(-50)*w%st%gsize) exit
         span = 0.5_dp*span
      end do
      call check(error, halvings <= 40 .and. span > 0.0_dp, "a sub-interval bounds the series")
   end subroutine oscillator

   !> u(s) = u0 cos(omega s) + v0/omega sin(omega s), its derivative, and the absolute
   !> acceleration -omega^2 u (no table motion), at points of the sub-interval; move_to
   !> leaves the state there, values_at gives the quantities there.
   subroutine test_free_oscillator(error)
      type(error_type), allocatable, intent(out) :: error
      type(ed_work) :: w
      type(model_type) :: model
      type(excitation_type) :: exc
      real(dp) :: omega, s, span, amp, ue, ve, y(3)
      integer :: j

      call oscillator(0.0_dp, 0.0_dp, w, model, exc, error)
      if (allocated(error)) return
      omega = sqrt(k/m)
      amp = sqrt(u0**2 + (v0/omega)**2)
      span = w%st%span
      call check(error, span > 0.01_dp/omega, "a sub-interval of more than 1/100 of a radian")
      if (allocated(error)) return
      do j = 1, 4
         s = span*j/4.0_dp
         ue = u0*cos(omega*s) + v0/omega*sin(omega*s)
         ve = -u0*omega*sin(omega*s) + v0*cos(omega*s)
         call values_at(w%st, s, y)
         call check_close(error, y(iq_u(1)), ue, 1e-14_dp*amp, "u at s", absolute=.true.)
         if (allocated(error)) return
         call check_close(error, y(iq_v(1)), ve, 1e-14_dp*amp*omega, "v at s", absolute=.true.)
         if (allocated(error)) return
         call check_close(error, y(iq_a(1)), -omega**2*ue, 1e-14_dp*amp*omega**2, "aabs at s", absolute=.true.)
         if (allocated(error)) return
      end do
      call move_to(w, span)
      call check_close(error, w%st%u(1), ue, 1e-14_dp*amp, "u after move_to", absolute=.true.)
      if (allocated(error)) return
      call check_close(error, w%st%v(1), ve, 1e-14_dp*amp*omega, "v after move_to", absolute=.true.)
   end subroutine test_free_oscillator

   !> m u'' + c u' + k u = -m ag: over [0, s] the change of m v^2/2 + k u^2/2 is the input
   !> work -int m ag v minus the viscous work int c v^2, which energy integrates exactly.
   subroutine test_energy_balance(error)
      type(error_type), allocatable, intent(out) :: error
      type(ed_work) :: w
      type(model_type) :: model
      type(excitation_type) :: exc
      type(result_type) :: res
      real(dp) :: e0, e1, s, c

      c = 2.0_dp*0.05_dp*sqrt(k*m)   ! 5 % of critical
      call oscillator(c, 0.03_dp, w, model, exc, error)
      if (allocated(error)) return
      allocate (w%mp(0:size(w%st%g) - 1), w%ein(0:2*(size(w%st%g) - 1)), w%evi(0:2*(size(w%st%g) - 1)))
      s = w%st%span
      e0 = 0.5_dp*m*v0**2 + 0.5_dp*k*u0**2
      call energy(w, res, s)
      call move_to(w, s)
      e1 = 0.5_dp*m*w%st%v(1)**2 + 0.5_dp*k*w%st%u(1)**2
      call check(error, res%e_viscous > 0.0_dp .and. res%e_input /= 0.0_dp, "both works are done")
      if (allocated(error)) return
      call check_close(error, res%e_input - res%e_viscous, e1 - e0, 1e-12_dp*e0, "work = energy change", &
                       absolute=.true.)
      if (allocated(error)) return
      call check_close(error, res%e_input_gross, abs(res%e_input), 0.0_dp, "gross input of one interval")
   end subroutine test_energy_balance

   !> Rows every `every` dt1 steps; the last one at nsteps, where the count does not divide.
   subroutine test_row_times(error)
      type(error_type), allocatable, intent(out) :: error
      type(ed_work) :: w
      integer :: j
      w%obs%every = 3
      w%obs%nsteps = 10
      w%h = 0.01_dp
      do j = 1, 3
         call check(error, next_row_time(w, j) == (3*j)*0.01_dp, "row at 3 j steps")
         if (allocated(error)) return
      end do
      call check(error, next_row_time(w, 4) == 10*0.01_dp, "the last row at nsteps")
      if (allocated(error)) return
      call check(error, next_row_time(w, 0) == 0.0_dp, "row 0 at t = 0")
   end subroutine test_row_times

   !> update_global takes |y| of every quantity at tp; a point before the sub-interval
   !> (s < 0) takes nothing.
   subroutine test_update_global(error)
      type(error_type), allocatable, intent(out) :: error
      type(ed_work) :: w
      type(result_type) :: res

      call two_dofs(w, res)
      allocate (w%yv(8))
      w%yv = [-1.0_dp, 2.0_dp, -3.0_dp, 4.0_dp, -5.0_dp, 6.0_dp, -7.0_dp, 8.0_dp]
      call update_global(w, res, -1.0_dp, 5.0_dp)
      call check(error, all(res%peak_u == 0.0_dp) .and. all(res%peak_force == 0.0_dp), "s < 0: nothing")
      if (allocated(error)) return
      call update_global(w, res, 0.0_dp, 5.0_dp)
      call check(error, all(res%peak_u == [1.0_dp, 4.0_dp]) .and. all(res%peak_v == [2.0_dp, 5.0_dp]) .and. &
                 all(res%peak_aabs == [3.0_dp, 6.0_dp]) .and. res%peak_s(1) == 7.0_dp .and. &
                 res%peak_force(1) == 8.0_dp .and. all(res%peak_u_time == 5.0_dp), "|y| at tp")
   end subroutine test_update_global

   !> y(x) = 1 - 4 (x - 1/2)^2 on a sub-interval from t = 2 s, u of DOF 1, its stationary
   !> points given at 0.25, 0.5 and 0.75: absorb_until(0.5) takes the first two (y = 0.75,
   !> 1), not the third; absorb_until(1) the third; the envelope is their maximum.
   subroutine test_absorb_until(error)
      type(error_type), allocatable, intent(out) :: error
      type(ed_work) :: w
      type(result_type) :: res

      call two_dofs(w, res)
      w%st%order = 2
      allocate (w%st%yc(0:2, 8), w%rts(3, 8), w%nrt(8), w%ip(8), w%env(8))
      w%st%yc = 0.0_dp
      w%st%yc(0:2, 1) = [0.0_dp, 4.0_dp, -4.0_dp]
      w%rts = 0.0_dp
      w%rts(:, 1) = [0.25_dp, 0.5_dp, 0.75_dp]
      w%nrt = 0
      w%nrt(1) = 3
      w%ip = 1
      w%env = 0.0_dp
      w%t = 2.0_dp
      call absorb_until(w, res, 0.5_dp)
      call check(error, w%ip(1) == 3 .and. w%env(1) == 1.0_dp, "two points up to 0.5")
      if (allocated(error)) return
      call check(error, res%peak_u(1) == 1.0_dp .and. res%peak_u_time(1) == 2.5_dp, "the peak at t + 0.5")
      if (allocated(error)) return
      call absorb_until(w, res, 0.7_dp)
      call check(error, w%ip(1) == 3, "none in (0.5, 0.7]")
      if (allocated(error)) return
      call absorb_until(w, res, 1.0_dp)
      call check(error, w%ip(1) == 4 .and. w%env(1) == 1.0_dp .and. res%peak_u_time(1) == 2.5_dp, &
                 "the third taken, the peak kept")
      if (allocated(error)) return
      call check(error, all(w%ip(2:) == 1) .and. all(w%env(2:) == 0.0_dp), "the other quantities untouched")
   end subroutine test_absorb_until

   !> The message starts with the technique and t, once; a cancel is left as it is.
   subroutine test_with_context(error)
      type(error_type), allocatable, intent(out) :: error
      type(ed_work) :: w
      type(fd_error_type), allocatable :: err
      character(len=:), allocatable :: want

      w%t = 1.25_dp
      call fatal_error(err, "boom")
      call with_context(w, err)
      want = "event-driven technique at t = "//trim(fmt_real(1.25_dp))//" s: boom"
      call check(error, err%message, want)
      if (allocated(error)) return
      call with_context(w, err)
      call check(error, err%message, want, "not said twice")
      if (allocated(error)) return
      deallocate (err)
      call fatal_error(err, "cancelled", stat_cancelled)
      call with_context(w, err)
      call check(error, err%message, "cancelled", "a cancel as it is")
   end subroutine test_with_context

   !> The error of a series no sub-interval bounds, as the run hands it back (with_context):
   !> the technique and the instant once, then the shortest sub-interval tried.
   subroutine test_unbounded_series(error)
      type(error_type), allocatable, intent(out) :: error
      type(ed_work) :: w
      type(fd_error_type), allocatable :: err

      w%t = 1.25_dp
      call unbounded_series(0.5_dp**40, err)
      call with_context(w, err)
      call check(error, err%message, "event-driven technique at t = "//trim(fmt_real(1.25_dp))//" s: the Taylor "// &
                 "series' remainder stays above the rounding level on sub-intervals down to "// &
                 trim(fmt_real(0.5_dp**40))//" s, so events cannot be located; use moreau_jean or the velocity law")
   end subroutine test_unbounded_series

   !> An error when t_end - t > 1e9 sub-intervals of the current pattern, naming its length;
   !> none at half of that.
   subroutine test_subinterval_budget(error)
      type(error_type), allocatable, intent(out) :: error
      type(ed_work) :: w
      type(model_type) :: model
      type(excitation_type) :: exc
      type(fd_error_type), allocatable :: err
      real(dp) :: delta

      call oscillator(0.0_dp, 0.0_dp, w, model, exc, error)
      if (allocated(error)) return
      delta = w%st%cache%slot(w%st%cur)%delta
      w%t = 1.0_dp
      w%t_end = 1.0_dp + 0.5e9_dp*delta
      call check_subintervals(w, err)
      call check(error, .not. allocated(err), "half the budget: no error")
      if (allocated(error)) return
      w%t_end = 1.0_dp + 2.0e9_dp*delta
      call check_subintervals(w, err)
      call check(error, allocated(err), "twice the budget: an error")
      if (allocated(error)) return
      call check(error, index(err%message, "needs sub-intervals of "//trim(fmt_real(delta))//" s") > 0, &
                 err%message)
   end subroutine test_subinterval_budget

   !> A block of mass 2 kg on a table at rest, sliding at v0 = 0.3 m/s against a Coulomb
   !> device of P mu = 2 N (no spring): it decelerates at 1 m/s2 and stops at t* = m v0 /
   !> (P mu) = 0.3 s, after u = v0 t* / 2 = 0.045 m, then sticks: one event, at t*, located
   !> by the loop (advance_run, event_at) where the velocity falls below minus its rounding
   !> level (a few 1e-14 s after t*).
   subroutine test_event_location(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(integration_type) :: opts
      type(result_type) :: res
      type(fd_error_type), allocatable :: err

      model%n_dof = 1
      model%mass = [2.0_dp]
      model%u0 = [0.0_dp]
      model%v0 = [0.3_dp]
      model%n_springs = 0
      allocate (model%spring_i(0), model%spring_j(0), model%spring_k(0))
      model%n_devices = 1
      model%dev = [device_type(node_i=1, node_j=0, law=law_coulomb, p=10.0_dp, mu=0.2_dp)]
      call pairs_of(model)
      exc%kind = excitation_harmonic
      exc%amplitude = 0.0_dp
      exc%frequency = 2.0_dp
      exc%dt_record = 0.007_dp
      exc%duration = 0.5_dp
      opts%n1 = 3
      call run_event_driven(model, exc, opts, res, err)
      if (allocated(err)) then
         call test_failed(error, err%message)
         return
      end if
      call check(error, res%exact%events, 1, "one event")
      if (allocated(error)) return
      call check_close(error, res%exact%event_time(1), 0.3_dp, 2e-13_dp, "at m v0 / (P mu)")   ! measured 5.3e-14
      if (allocated(error)) return
      call check_close(error, res%peak_u(1), 0.045_dp, 4.0_dp*epsilon(1.0_dp), "u = v0 t* / 2")
      if (allocated(error)) return
      call check_close(error, res%peak_u_time(1), 0.3_dp, 2e-13_dp, "reached when it stops")
   end subroutine test_event_location

   !> The work of two DOFs and one device (8 quantities, no storeys) and its summary peaks.
   subroutine two_dofs(w, res)
      type(ed_work), intent(out) :: w
      type(result_type), intent(out) :: res
      w%st%n = 2
      w%st%nd = 1
      w%st%nbase = 8
      w%st%nquant = 8
      res%n_dof = 2
      res%n_devices = 1
      allocate (res%peak_u(2), res%peak_u_time(2), res%peak_v(2), res%peak_aabs(2), res%peak_aabs_time(2), &
                res%peak_s(1), res%peak_force(1))
      res%peak_u = 0.0_dp; res%peak_u_time = 0.0_dp; res%peak_v = 0.0_dp
      res%peak_aabs = 0.0_dp; res%peak_aabs_time = 0.0_dp
      res%peak_s = 0.0_dp; res%peak_force = 0.0_dp
   end subroutine two_dofs

end module test_fd_event_driven
