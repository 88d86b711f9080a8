!> What each technique did, counted by its own loop in its own small type: Newmark's steps of
!> each size, refinements and factorizations; the exact technique's sampling intervals,
!> matrix exponentials, events and accumulation points; Moreau-Jean's steps, factorizations,
!> patterns and Lemke fallbacks. Each counter means one thing. Each type also keeps what the
!> technique's set-up fixed (run_setup: its steps, the stuck system's first mode, what its rule
!> means for the energy balance), from which the summary writes period_stuck_s ... dt_min_s and
!> the energy balance's check judges (technique_setup). The summary's counter keys
!> (steps_dt1 ... lcp_fallbacks) are one table for every technique: each type
!> says which of its counters goes under which key (its *_counts function), and a technique's
!> part of the summary writes that table (fd_output).
module fd_statistics
   use fd_kinds, only: dp
   implicit none
   private

   public :: newmark_stats, event_driven_stats, moreau_jean_stats, summary_counts, run_setup
   public :: technique_setup
   public :: newmark_counts, event_driven_counts, moreau_jean_counts, technique_counts
   public :: count_event, count_accumulation
   public :: max_event_times, max_accumulation_times

   integer, parameter :: max_event_times = 1000       !! first event times kept (exact technique)
   integer, parameter :: max_accumulation_times = 10  !! first accumulation times kept

   !> What a technique's set-up fixed: its steps, the stuck system's first mode (as the
   !> technique builds its matrices) and what its rule means for the energy balance.
   type :: run_setup
      real(dp) :: dt1 = 0.0_dp          !! main step (the exact technique: its sampling interval) [s]
      real(dp) :: dt2 = 0.0_dp          !! step around phase changes (0: none) [s]
      real(dp) :: dt_min = 0.0_dp       !! floor of step halving (0: none) [s]
      real(dp) :: period_stuck = 0.0_dp !! first period of the stuck system [s] (0: none)
      real(dp) :: xi_stuck = 0.0_dp     !! damping ratio of that mode [-]
      logical :: damping_method = .false.   !! the rule damps numerically (gamma or theta > 1/2)
      logical :: exact_accounting = .false. !! its energy residual is round-off (average acceleration)
   end type run_setup

   !> The Newmark technique (fd_newmark).
   type :: newmark_stats
      logical :: ran = .false.         !! the run was Newmark's
      type(run_setup) :: setup         !! its steps dt1, dt2, dt_min and the stuck system's mode
      integer :: steps_dt1 = 0         !! steps taken whole with dt1
      integer :: steps_dt2 = 0         !! steps taken with dt2
      integer :: steps_nested = 0      !! steps of the sizes between dt1 and dt2 (refinement 'nested')
      integer :: steps_implicit = 0    !! dt1 steps taken in the phases they end in (refinement 'implicit')
      integer :: implicit_redos = 0    !! trial steps redone to settle the phases (refinement 'implicit')
      integer :: implicit_fallbacks = 0 !! dt1 steps whose phases did not settle, refined as 'step'
      integer :: steps_finer = 0       !! steps taken with dt2/2, dt2/4, ...
      integer :: factorizations = 0    !! factorizations of the effective stiffness
      integer :: factor_updates = 0    !! rank-one updates and downdates of the factor (phase changes)
      integer :: partial_factorizations = 0 !! refactorizations from the first changed column on
      integer :: storage = 0           !! effective stiffness stored 1 dense, 2 banded (0: none)
      integer :: bandwidth = 0         !! its half-bandwidth in the solver's ordering
      integer :: mu_passes = 0         !! solves of the fixed point on the sliding forces (a
                                       !! speed-dependent mu)
   end type newmark_stats

   !> The exact event-driven technique (fd_event_driven).
   type :: event_driven_stats
      logical :: ran = .false.         !! the run was the exact technique's
      type(run_setup) :: setup         !! its sampling interval and the stuck system's mode
      integer :: intervals = 0         !! sampling intervals dt1 integrated
      integer :: exponentials = 0      !! matrix exponentials built (one per phase pattern met)
      integer :: events = 0            !! events located: instants at which phases changed
      integer :: n_event_times = 0     !! entries used in event_time
      real(dp) :: event_time(max_event_times) = 0.0_dp !! times of the first events [s]
      integer :: accumulations = 0     !! accumulation points of events (Zeno), handled
      integer :: n_accumulation_times = 0 !! entries used in accumulation_time
      real(dp) :: accumulation_time(max_accumulation_times) = 0.0_dp !! their first times [s]
   end type event_driven_stats

   !> The Moreau-Jean technique (fd_moreau_jean).
   type :: moreau_jean_stats
      logical :: ran = .false.         !! the run was Moreau-Jean's
      type(run_setup) :: setup         !! its step and the stuck system's mode
      integer :: steps = 0             !! time steps taken (each of dt1)
      integer :: factorizations = 0    !! factorizations of the stick groups' systems
      integer :: patterns = 0          !! stick-slip patterns solved in one-step problems
      integer :: lcp_fallbacks = 0     !! one-step problems that needed Lemke's fallback
      integer :: storage = 0           !! the general form's W stored 1 dense, 2 banded (0: the
                                       !! stick groups' form, no W of the whole model)
      integer :: bandwidth = 0         !! its half-bandwidth in the solver's ordering
   end type moreau_jean_stats

   !> The summary's counter keys, one table for every technique (0: not the technique's).
   type :: summary_counts
      integer :: steps_dt1 = 0, steps_nested = 0, steps_implicit = 0, implicit_redos = 0
      integer :: implicit_fallbacks = 0, steps_dt2 = 0, steps_finer = 0, factorizations = 0
      integer :: factor_updates = 0, partial_factorizations = 0, storage = 0, bandwidth = 0
      integer :: events = 0, patterns = 0, lcp_fallbacks = 0
   end type summary_counts

contains

   !> Newmark's counters under the summary's keys (each under its own name).
   pure function newmark_counts(st) result(c)
      type(newmark_stats), intent(in) :: st   !! Newmark's statistics
      type(summary_counts) :: c               !! the summary's counters

      c = summary_counts(steps_dt1=st%steps_dt1, steps_nested=st%steps_nested, steps_implicit=st%steps_implicit, &
                         implicit_redos=st%implicit_redos, implicit_fallbacks=st%implicit_fallbacks, &
                         steps_dt2=st%steps_dt2, steps_finer=st%steps_finer, factorizations=st%factorizations, &
                         factor_updates=st%factor_updates, partial_factorizations=st%partial_factorizations, &
                         storage=st%storage, bandwidth=st%bandwidth)
   end function newmark_counts

   !> The exact technique's counters under the summary's keys: its sampling intervals as
   !> steps_dt1, its matrix exponentials as factorizations, its events.
   pure function event_driven_counts(st) result(c)
      type(event_driven_stats), intent(in) :: st   !! the exact technique's statistics
      type(summary_counts) :: c                    !! the summary's counters

      c%steps_dt1 = st%intervals
      c%factorizations = st%exponentials
      c%events = st%events
   end function event_driven_counts

   !> Moreau-Jean's counters under the summary's keys: its steps as steps_dt1, its
   !> factorizations, patterns_solved and lcp_fallbacks.
   pure function moreau_jean_counts(st) result(c)
      type(moreau_jean_stats), intent(in) :: st   !! Moreau-Jean's statistics
      type(summary_counts) :: c                   !! the summary's counters

      c%steps_dt1 = st%steps
      c%factorizations = st%factorizations
      c%patterns = st%patterns
      c%lcp_fallbacks = st%lcp_fallbacks
      c%storage = st%storage
      c%bandwidth = st%bandwidth
   end function moreau_jean_counts

   !> The summary's counters of the technique that ran (all 0 when none did).
   pure function technique_counts(newmark, exact, mj) result(c)
      type(newmark_stats), intent(in) :: newmark      !! Newmark's statistics
      type(event_driven_stats), intent(in) :: exact   !! the exact technique's
      type(moreau_jean_stats), intent(in) :: mj       !! Moreau-Jean's
      type(summary_counts) :: c                       !! the summary's counters

      if (newmark%ran) then
         c = newmark_counts(newmark)
      else if (exact%ran) then
         c = event_driven_counts(exact)
      else if (mj%ran) then
         c = moreau_jean_counts(mj)
      end if
   end function technique_counts

   !> What the set-up of the technique that ran fixed (all 0 when none ran).
   pure function technique_setup(newmark, exact, mj) result(s)
      type(newmark_stats), intent(in) :: newmark      !! Newmark's statistics
      type(event_driven_stats), intent(in) :: exact   !! the exact technique's
      type(moreau_jean_stats), intent(in) :: mj       !! Moreau-Jean's
      type(run_setup) :: s                            !! its set-up

      if (newmark%ran) then
         s = newmark%setup
      else if (exact%ran) then
         s = exact%setup
      else if (mj%ran) then
         s = mj%setup
      end if
   end function technique_setup

   !> An event at time t (phases changed): counted, its time kept (the first max_event_times).
   pure subroutine count_event(st, t)
      type(event_driven_stats), intent(inout) :: st   !! the exact technique's statistics
      real(dp), intent(in) :: t                       !! time of the event [s]

      st%events = st%events + 1
      if (st%n_event_times >= max_event_times) return
      st%n_event_times = st%n_event_times + 1
      st%event_time(st%n_event_times) = t
   end subroutine count_event

   !> An accumulation point of events (a Zeno sequence) at time t, ended by sticking.
   pure subroutine count_accumulation(st, t)
      type(event_driven_stats), intent(inout) :: st   !! the exact technique's statistics
      real(dp), intent(in) :: t                       !! its time [s]

      st%accumulations = st%accumulations + 1
      if (st%n_accumulation_times >= max_accumulation_times) return
      st%n_accumulation_times = st%n_accumulation_times + 1
      st%accumulation_time(st%n_accumulation_times) = t
   end subroutine count_accumulation

end module fd_statistics
