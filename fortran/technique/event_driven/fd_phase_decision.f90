!> The event and phase decision of the exact technique at an instant: the forces that keep
!> the sticking devices stuck, the event functions whose zeros are the events, and the
!> decision of which devices stick and which slide (decide_phases: the one call a
!> complementarity solver replaces).
module fd_phase_decision
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real
   use fd_model, only: model_type
   use fd_excitation, only: excitation_type, table_motion
   use fd_kinematics, only: device_relative, add_device
   use fd_linalg, only: sym_matvec, least_squares
   use fd_device_state, only: phase_stick
   use fd_ed_state, only: ed_state, set_pattern, expand_state
   implicit none
   private

   public :: decide_phases, stuck_forces, event_values

   real(dp), parameter :: at_limit = 1.0_dp - 1.0e-9_dp  !! |F| / P mu that counts as the limit

contains

   !> Forces of the devices at the expanded state (st%u, v, acc at time t): P mu sgn s' for
   !> a sliding device, 0 for an inactive one, and for the sticking ones the forces that
   !> keep them stuck, B F = p - M a - C v - K u - sum_slip b P mu sgn, solved in the
   !> least-squares sense (minimum norm for a statically indeterminate loop).
   subroutine stuck_forces(model, exc, t, st, error)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      real(dp), intent(in) :: t                     !! time [s]
      type(ed_state), intent(inout) :: st           !! the state: force set
      type(error_type), allocatable, intent(out) :: error !! failure of the least-squares solve
      real(dp) :: xg, vg, ag
      integer :: d, k, info

      do d = 1, st%nd
         if (.not. st%active(d)) then
            st%force(d) = 0.0_dp
         else if (st%phase(d) /= phase_stick) then
            st%force(d) = st%phase(d)*st%slip(d)
         end if
      end do
      if (st%ns == 0) return
      call table_motion(exc, t, xg, vg, ag)
      associate (r => st%rr, bm => st%bm)
         r(1:st%n, 1) = -st%mass*(ag + st%acc)
         call sym_matvec(st%c, st%v, r(1:st%n, 1), -1.0_dp, 1.0_dp)
         call sym_matvec(st%k, st%u, r(1:st%n, 1), -1.0_dp, 1.0_dp)
         do d = 1, st%nd
            if (st%active(d) .and. st%phase(d) /= phase_stick) call add_device(model, d, -st%force(d), r(1:st%n, 1))
         end do
         bm = 0.0_dp
         do k = 1, st%ns
            call add_device(model, st%ids(k), 1.0_dp, bm(:, k))
         end do
         call least_squares(bm, r, st%sv, st%lwk, info)
         if (info /= 0) then
            call fatal_error(error, "event-driven technique: the least-squares solve for the forces of "// &
                             trim(fmt_int(st%ns))//" sticking devices failed at t = "//trim(fmt_real(t))// &
                             " s (LAPACK dgelss info = "//trim(fmt_int(info))//")")
            return
         end if
         do k = 1, st%ns
            st%force(st%ids(k)) = r(k, 1)
         end do
      end associate
   end subroutine stuck_forces

   !> Event functions at the expanded state, with the forces set: sliding devices sgn s'
   !> (> 0 while sliding on), sticking devices P mu - |F| (> 0 while the device holds),
   !> inactive devices 1. An event is a zero of one of them.
   pure subroutine event_values(model, st, g)
      type(model_type), intent(in) :: model         !! the model
      type(ed_state), intent(in) :: st              !! the state
      real(dp), intent(out) :: g(:)                 !! event function of each device
      integer :: d

      do d = 1, st%nd
         if (.not. st%active(d)) then
            g(d) = 1.0_dp
         else if (st%phase(d) == phase_stick) then
            g(d) = st%slip(d) - abs(st%force(d))
         else
            g(d) = st%phase(d)*device_relative(model, d, st%v)
         end if
      end do
   end subroutine event_values

   !> Decide the phases at an instant. On entry st holds the state at t (u, v) and the
   !> phases before t (phase; fresh: slides begun at s' = 0 at this instant); on return
   !> the phases decided, their pattern, the reduced state x, u, v (projected on the
   !> constraints), acc and the device forces at t.
   !>
   !> The rule (docs/theory.md, section 9): candidates for sticking are the sticking
   !> devices and the sliding ones at a velocity zero; the forces that keep all candidates
   !> stuck come from one least-squares solve; the candidate needing most above P mu
   !> slides in the direction of its force (kept only if the device then accelerates that
   !> way), and the solve is repeated; then every device that began sliding is checked
   !> again. A greedy rule, not a complete solution of the complementarity problem.
   subroutine decide_phases(model, exc, t, st, error)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      real(dp), intent(in) :: t                     !! time [s]
      type(ed_state), intent(inout) :: st           !! the state, with the phases decided
      type(error_type), allocatable, intent(out) :: error !! no steady state, failed solve
      logical, allocatable :: held(:)
      real(dp) :: ratio, worst, sd
      integer :: d, dw, iter, pass

      allocate (held(st%nd))
      dw = 0
      held = .false.
      ! the state is expanded at t; candidates: stuck ones, and sliders at a velocity zero
      do d = 1, st%nd
         if (.not. st%active(d) .or. st%phase(d) == phase_stick) cycle
         sd = st%phase(d)*device_relative(model, d, st%v)
         if (sd <= 0.0_dp .and. .not. st%fresh(d)) st%phase(d) = phase_stick
      end do
      ! release, one at a time, the candidate that needs most above P mu (at the limit counts:
      ! its force got there increasing), in the direction of its force; keep the release only
      ! if the device then accelerates that way, else it holds
      do pass = 1, st%nd + 1
         dw = 0
         do iter = 1, 2*st%nd + 2
            call set_pattern(model, exc, t, st, error)
            if (allocated(error)) return
            call expand_state(exc, t, st)
            call stuck_forces(model, exc, t, st, error)
            if (allocated(error)) return
            if (dw > 0) then
               if (st%phase(dw)*device_relative(model, dw, st%acc) <= 0.0_dp) then
                  st%phase(dw) = phase_stick
                  st%fresh(dw) = .false.
                  held(dw) = .true.
                  dw = 0
                  cycle
               end if
            end if
            worst = at_limit
            dw = 0
            do d = 1, st%nd
               if (.not. st%active(d) .or. st%phase(d) /= phase_stick .or. held(d)) cycle
               ratio = abs(st%force(d))/st%slip(d)
               if (ratio >= worst) then
                  worst = ratio
                  dw = d
               end if
            end do
            if (dw == 0) exit
            st%phase(dw) = int(sign(1.0_dp, st%force(dw)))
            st%fresh(dw) = .true.
         end do
         ! a device released earlier may no longer accelerate in its direction once others
         ! were released: it holds, and the decision is made again
         dw = 0
         worst = 0.0_dp
         do d = 1, st%nd
            if (.not. st%fresh(d) .or. st%phase(d) == phase_stick) cycle
            ratio = st%phase(d)*device_relative(model, d, st%acc)
            if (ratio <= worst) then
               worst = ratio
               dw = d
            end if
         end do
         if (dw == 0) exit
         st%phase(dw) = phase_stick
         st%fresh(dw) = .false.
         held(dw) = .true.
      end do
      if (dw /= 0) then
         ! out of passes: leave the state consistent with the phases decided last
         call set_pattern(model, exc, t, st, error)
         if (allocated(error)) return
         call expand_state(exc, t, st)
         call stuck_forces(model, exc, t, st, error)
         if (allocated(error)) return
      end if
      do d = 1, st%nd
         if (st%phase(d) /= phase_stick) cycle
         st%fresh(d) = .false.
      end do
   end subroutine decide_phases

end module fd_phase_decision
