!> The record every check of a run fills, whatever it checks (the correctness condition, a
!> speed-dependent mu, the resolution of the highest modes, of a harmonic or recorded table
!> motion and of the sticking springs' ringing, a velocity-law band's alternation, the energy
!> balance): its key (the summary key of its verdict), its verdict (not applicable, passed,
!> warns), the figures it judged by (name and value pairs, named as the summary keys they
!> come from where there is one), the word the summary writes for its verdict (its outcome:
!> 'resolved', 'closed', 'passed' ...) and, when it warns, its warning's one line. The warnings of
!> a run are a filter over its checks (check_warnings): each check that warns gives its
!> line, in the order of the checks.
module fd_check
   use fd_kinds, only: dp
   implicit none
   private

   public :: check_type, warning_text, add_figure, figure_of, check_warnings, check_warns, outcome_of
   public :: verdict_not_applicable, verdict_passed, verdict_warns, verdict_names
   public :: check_key_len, figure_name_len, max_figures, outcome_len

   integer, parameter :: check_key_len = 24     !! length of a check's key
   integer, parameter :: figure_name_len = 32   !! length of a figure's name
   integer, parameter :: max_figures = 8        !! figures a check keeps
   integer, parameter :: outcome_len = 14       !! length of a verdict's word in the summary

   integer, parameter :: verdict_not_applicable = 1 !! the check does not apply to the run
   integer, parameter :: verdict_passed = 2         !! it applies and the run passes it
   integer, parameter :: verdict_warns = 3          !! the run's answer needs care: a warning
   !> their names
   character(len=14), parameter :: verdict_names(3) = [character(len=14) :: 'not applicable', 'passed', 'warns']

   !> One check of a run.
   type :: check_type
      character(len=check_key_len) :: key = ''      !! the summary key of its verdict
      integer :: verdict = verdict_not_applicable   !! verdict_*
      character(len=outcome_len) :: outcome = 'not applicable' !! the summary's word for it
      integer :: n_figures = 0                      !! figures used
      character(len=figure_name_len) :: figure_name(max_figures) = '' !! their names
      real(dp) :: figure(max_figures) = 0.0_dp      !! their values
      character(len=:), allocatable :: warning      !! the warning's line (verdict_warns only)
   end type check_type

   !> One warning's text, without the executable's "frictiondyn: warning: ".
   type :: warning_text
      character(len=:), allocatable :: text
   end type warning_text

contains

   !> One more figure of a check (beyond max_figures: not kept).
   pure subroutine add_figure(c, name, value)
      type(check_type), intent(inout) :: c   !! the check
      character(len=*), intent(in) :: name   !! the figure's name
      real(dp), intent(in) :: value          !! its value

      if (c%n_figures >= max_figures) return
      c%n_figures = c%n_figures + 1
      c%figure_name(c%n_figures) = name
      c%figure(c%n_figures) = value
   end subroutine add_figure

   !> The check's figure of that name; `found` false (and 0) when it has none.
   pure subroutine figure_of(c, name, value, found)
      type(check_type), intent(in) :: c      !! the check
      character(len=*), intent(in) :: name   !! the figure's name
      real(dp), intent(out) :: value         !! its value
      logical, intent(out) :: found          !! the check has it
      integer :: k

      value = 0.0_dp
      found = .false.
      do k = 1, c%n_figures
         if (c%figure_name(k) /= name) cycle
         value = c%figure(k)
         found = .true.
         return
      end do
   end subroutine figure_of

   !> The summary's word for the verdict of the check of that key (blank: no such check).
   pure function outcome_of(checks, key) result(word)
      type(check_type), intent(in) :: checks(:)   !! the run's checks
      character(len=*), intent(in) :: key         !! a check's key
      character(len=outcome_len) :: word          !! its outcome
      integer :: k

      word = ''
      do k = 1, size(checks)
         if (checks(k)%key /= key) cycle
         word = checks(k)%outcome
         return
      end do
   end function outcome_of

   !> Whether the check warns (its verdict is verdict_warns and it has a line).
   pure logical function check_warns(c)
      type(check_type), intent(in) :: c   !! the check

      check_warns = c%verdict == verdict_warns .and. allocated(c%warning)
   end function check_warns

   !> The warnings of a run: the line of each check that warns, in the order of the checks
   !> (none: an empty array).
   pure subroutine check_warnings(checks, w)
      type(check_type), intent(in) :: checks(:)             !! the run's checks
      type(warning_text), allocatable, intent(out) :: w(:)  !! their warnings
      integer :: k, n

      allocate (w(count([(check_warns(checks(k)), k=1, size(checks))])))
      n = 0
      do k = 1, size(checks)
         if (.not. check_warns(checks(k))) cycle
         n = n + 1
         w(n)%text = checks(k)%warning
      end do
   end subroutine check_warnings

end module fd_check
