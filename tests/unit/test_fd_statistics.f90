!> Unit tests of the techniques' statistics (fd_statistics): events and accumulation points
!> counted with their first times kept; each technique's counters under the summary's keys
!> (the exact technique's matrix exponentials as factorizations, Moreau-Jean's steps as
!> steps_dt1); the counters of the technique that ran, none when none did.
module test_fd_statistics
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_statistics, only: newmark_stats, event_driven_stats, moreau_jean_stats, summary_counts, &
                            technique_counts, technique_setup, run_setup, count_event, count_accumulation, max_event_times, &
                            max_accumulation_times
   implicit none
   private

   public :: collect_statistics

contains

   subroutine collect_statistics(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("events: all counted, the first times kept", test_events), &
                  new_unittest("each technique's counters under the summary's keys", test_counts), &
                  new_unittest("the set-up of the technique that ran", test_setup) &
                  ]
   end subroutine collect_statistics

   subroutine test_events(error)
      type(error_type), allocatable, intent(out) :: error
      type(event_driven_stats) :: st
      integer :: k

      do k = 1, max_event_times + 5
         call count_event(st, 0.001_dp*k)
      end do
      call check(error, st%events, max_event_times + 5)
      if (allocated(error)) return
      call check(error, st%n_event_times == max_event_times .and. &
                 st%event_time(max_event_times) == 0.001_dp*max_event_times, 'the first times kept')
      if (allocated(error)) return
      do k = 1, max_accumulation_times + 2
         call count_accumulation(st, 1.0_dp*k)
      end do
      call check(error, st%accumulations == max_accumulation_times + 2 .and. &
                 st%n_accumulation_times == max_accumulation_times .and. st%accumulation_time(1) == 1.0_dp, &
                 'accumulation points')
   end subroutine test_events

   !> None ran: zeros; the technique that ran gives its steps and stuck mode, not another's.
   subroutine test_setup(error)
      type(error_type), allocatable, intent(out) :: error
      type(newmark_stats) :: nm
      type(event_driven_stats) :: ed
      type(moreau_jean_stats) :: mj
      type(run_setup) :: s

      nm%setup%dt1 = 0.02_dp        ! counted only once Newmark ran
      mj%setup%dt1 = 0.005_dp
      mj%setup%period_stuck = 0.4_dp
      mj%setup%damping_method = .true.
      s = technique_setup(nm, ed, mj)
      call check(error, s%dt1 == 0.0_dp .and. s%period_stuck == 0.0_dp .and. .not. s%damping_method, 'none ran')
      if (allocated(error)) return
      mj%ran = .true.
      s = technique_setup(nm, ed, mj)
      call check(error, s%dt1 == 0.005_dp .and. s%period_stuck == 0.4_dp .and. s%damping_method .and. &
                 s%dt2 == 0.0_dp .and. .not. s%exact_accounting, "Moreau-Jean's")
   end subroutine test_setup

   subroutine test_counts(error)
      type(error_type), allocatable, intent(out) :: error
      type(newmark_stats) :: nm
      type(event_driven_stats) :: ed
      type(moreau_jean_stats) :: mj
      type(summary_counts) :: c

      c = technique_counts(nm, ed, mj)
      call check(error, c%steps_dt1 == 0 .and. c%factorizations == 0 .and. c%events == 0, 'none ran: zeros')
      if (allocated(error)) return
      ed%ran = .true.
      ed%intervals = 400
      ed%exponentials = 3
      call count_event(ed, 0.5_dp)
      c = technique_counts(nm, ed, mj)
      call check(error, c%steps_dt1 == 400 .and. c%factorizations == 3 .and. c%events == 1 .and. &
                 c%steps_dt2 == 0, 'the exact technique')
      if (allocated(error)) return
      ed%ran = .false.
      mj%ran = .true.
      mj%steps = 100
      mj%factorizations = 2
      mj%patterns = 7
      mj%lcp_fallbacks = 1
      c = technique_counts(nm, ed, mj)
      call check(error, c%steps_dt1 == 100 .and. c%factorizations == 2 .and. c%patterns == 7 .and. &
                 c%lcp_fallbacks == 1 .and. c%events == 0, 'Moreau-Jean')
      if (allocated(error)) return
      mj%ran = .false.
      nm%ran = .true.
      nm%steps_dt1 = 90
      nm%steps_dt2 = 20
      nm%steps_nested = 5
      nm%factorizations = 4
      nm%storage = 2
      nm%bandwidth = 3
      c = technique_counts(nm, ed, mj)
      call check(error, c%steps_dt1 == 90 .and. c%steps_dt2 == 20 .and. c%steps_nested == 5 .and. &
                 c%factorizations == 4 .and. c%storage == 2 .and. c%bandwidth == 3 .and. c%patterns == 0, 'Newmark')
   end subroutine test_counts

end module test_fd_statistics
