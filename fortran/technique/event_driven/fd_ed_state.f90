!> The state of the exact event-driven technique at an instant: the structure's matrices,
!> the full state (u, v, relative acceleration) and the reduced state x of the current
!> phase pattern, the devices' phases and forces, and the work arrays sized with the
!> pattern, so that a step between events allocates nothing.
module fd_ed_state
   use fd_kinds, only: dp
   use fd_error, only: error_type
   use fd_model, only: model_type
   use fd_excitation, only: excitation_type
   use fd_linalg, only: least_squares_work
   use fd_device_state, only: phase_stick
   use fd_phase_pattern, only: pattern_type, build_pattern, expand_pattern, pattern_propagators
   implicit none
   private

   public :: ed_state, ed_setup, set_pattern, expand_state, step_propagators

   !> State of the exact technique.
   type :: ed_state
      integer :: n = 0, nd = 0                             !! DOFs, devices
      real(dp), allocatable :: mass(:), k(:, :), c(:, :)   !! structure
      real(dp), allocatable :: u(:), v(:), acc(:)          !! full state and relative acceleration
      real(dp), allocatable :: x(:)                        !! reduced state
      integer, allocatable :: phase(:)                     !! 0 stick, +-1 slip
      logical, allocatable :: fresh(:)                     !! slip started at s' = 0 this event
      logical, allocatable :: active(:)                    !! P mu > 0
      real(dp), allocatable :: force(:)                    !! device forces (stuck: required)
      real(dp), allocatable :: slip(:)                     !! P mu
      type(pattern_type) :: pat                            !! the current phase pattern
      integer :: n_expm = 0                                !! matrix exponentials computed
      ! work sized with each pattern (m = 2 nq)
      real(dp), allocatable :: ph(:, :), q1(:, :), q2(:, :)   !! propagators over tau_ph
      real(dp) :: tau_ph = -1.0_dp                            !! their step (-1: none)
      real(dp), allocatable :: pg(:, :), pq1(:, :), pq2(:, :) !! propagators at a quadrature node
      real(dp), allocatable :: y(:), y2(:), wk(:), xdot(:)    !! states and work (m)
      ! least-squares work of the stuck forces, sized with each pattern
      integer :: ns = 0                                       !! sticking active devices
      integer, allocatable :: ids(:)                          !! their indices
      real(dp), allocatable :: bm(:, :), rr(:, :), sv(:), lwk(:) !! least-squares work
   end type ed_state

contains

   !> Allocate the state of a model (stat /= 0: not enough memory for the matrices).
   subroutine ed_setup(model, st, stat)
      type(model_type), intent(in) :: model   !! the model
      type(ed_state), intent(inout) :: st     !! the state
      integer, intent(out) :: stat            !! allocation status
      integer :: n, nd, d

      n = model%n_dof
      nd = model%n_devices
      st%n = n
      st%nd = nd
      st%mass = model%mass
      allocate (st%k(n, n), st%c(n, n), st%u(n), st%v(n), st%acc(n), stat=stat)
      if (stat /= 0) return
      allocate (st%phase(nd), st%fresh(nd), st%active(nd), st%force(nd), st%slip(nd))
      st%fresh = .false.
      st%force = 0.0_dp
      do d = 1, nd
         st%slip(d) = model%dev(d)%p*model%dev(d)%mu
         st%active(d) = st%slip(d) > 0.0_dp
      end do
   end subroutine ed_setup

   !> Build the pattern of the current phases at time t (reduced state from u, v; v
   !> projected on the constraints) and size the work arrays with it.
   subroutine set_pattern(model, exc, t, st, error)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      real(dp), intent(in) :: t                     !! time [s]
      type(ed_state), intent(inout) :: st           !! the state
      type(error_type), allocatable, intent(out) :: error !! no steady state of the forcing
      integer :: m, n, ns, d

      call build_pattern(model, st%mass, st%k, st%c, st%active, st%phase, st%slip, exc, t, st%u, st%v, &
                         st%x, st%pat, error)
      if (allocated(error)) return
      m = st%pat%m
      n = st%n
      if (allocated(st%ph)) deallocate (st%ph, st%q1, st%q2, st%pg, st%pq1, st%pq2, st%y, st%y2, st%wk, st%xdot)
      allocate (st%ph(m, m), st%q1(m, m), st%q2(m, m), st%pg(m, m), st%pq1(m, m), st%pq2(m, m), &
                st%y(m), st%y2(m), st%wk(m), st%xdot(m))
      st%tau_ph = -1.0_dp
      ns = count(st%active .and. st%phase == phase_stick)
      st%ns = ns
      if (allocated(st%ids)) deallocate (st%ids, st%bm, st%rr, st%sv, st%lwk)
      allocate (st%ids(ns), st%bm(n, ns), st%rr(max(n, ns), 1), st%sv(max(1, min(n, ns))))
      ns = 0
      do d = 1, st%nd
         if (.not. st%active(d) .or. st%phase(d) /= phase_stick) cycle
         ns = ns + 1
         st%ids(ns) = d
      end do
      allocate (st%lwk(least_squares_work(n, ns)))
   end subroutine set_pattern

   !> Full u, v and relative acceleration at time t from the reduced state x (or, with
   !> trial, from the trial state y).
   subroutine expand_state(exc, t, st, trial)
      type(excitation_type), intent(in) :: exc      !! the table motion
      real(dp), intent(in) :: t                     !! time [s]
      type(ed_state), intent(inout) :: st           !! the state: u, v, acc set
      logical, intent(in), optional :: trial        !! expand y, not x

      if (present(trial)) then
         if (trial) then
            call expand_pattern(exc, st%pat, t, st%y, st%u, st%v, st%acc, st%xdot)
            return
         end if
      end if
      call expand_pattern(exc, st%pat, t, st%x, st%u, st%v, st%acc, st%xdot)
   end subroutine expand_state

   !> Make ph, q1, q2 the propagators over tau (those kept for the full step h if tau = h).
   subroutine step_propagators(st, tau, h, error)
      type(ed_state), intent(inout) :: st           !! the state
      real(dp), intent(in) :: tau                   !! time step [s]
      real(dp), intent(in) :: h                     !! the full step [s]
      type(error_type), allocatable, intent(out) :: error !! failure of an exponential

      st%tau_ph = -1.0_dp
      call pattern_propagators(st%pat, tau, h, st%ph, st%q1, st%q2, st%n_expm, error)
      if (allocated(error)) return
      st%tau_ph = tau
   end subroutine step_propagators

end module fd_ed_state
