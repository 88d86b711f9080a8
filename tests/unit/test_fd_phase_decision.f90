!> Unit tests of the exact technique's phase decision (fd_phase_decision) against what
!> Coulomb's law says in closed form for a block of mass m on a harmonically moving table,
!> held by friction devices (no spring, at rest relative to the table): it sticks while
!> m |ag| < P mu, with the force -m ag, and slides against the table's acceleration beyond;
!> at m |ag| = P mu exactly the next derivative decides (it slides while |ag| grows and
!> sticks while it falls); two devices in parallel share the load in proportion to their
!> limits and slide together once it exceeds their sum.
module test_fd_phase_decision
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_model, only: model_type, device_type, law_coulomb
   use fd_excitation, only: excitation_type, excitation_harmonic, table_motion
   use fd_device_state, only: phase_stick
   use fd_ed_state, only: ed_state, ed_setup
   use fd_phase_decision, only: decide_phases
   use test_fd_helpers, only: check_close, pairs_of
   implicit none
   private

   public :: collect_phase_decision

   real(dp), parameter :: pi = acos(-1.0_dp)
   real(dp), parameter :: m = 2.0_dp           !! the block [kg]
   real(dp), parameter :: amp = 0.01_dp        !! the table's amplitude [m] (2 Hz: |ag| <= 1.58 m/s2)
   real(dp), parameter :: freq = 2.0_dp        !! [Hz]

contains

   subroutine collect_phase_decision(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("a block sticks below P mu with F = -m ag", test_sticks), &
                  new_unittest("a block slides against the table beyond P mu", test_slides), &
                  new_unittest("at P mu exactly: slides while |ag| grows", test_limit_growing), &
                  new_unittest("at P mu exactly: sticks while |ag| falls", test_limit_falling), &
                  new_unittest("two devices in parallel share in proportion", test_parallel) &
                  ]
   end subroutine collect_phase_decision

   !> The block on the table through devices of limits slip (node 1 to the table), at rest
   !> relative to it, each device sticking before the decision.
   subroutine block(slip, st, exc, error)
      real(dp), intent(in) :: slip(:)
      type(ed_state), intent(out) :: st
      type(excitation_type), intent(out) :: exc
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(fd_error_type), allocatable :: err
      integer :: d

      call block_model(slip, model)
      exc%kind = excitation_harmonic
      exc%amplitude = amp
      exc%frequency = freq
      call ed_setup(model, st, 0, err)
      if (allocated(err)) then
         call test_failed(error, err%message)
         return
      end if
      st%k = 0.0_dp
      st%c = 0.0_dp
      st%u = 0.0_dp
      st%v = 0.0_dp
      do d = 1, size(slip)
         st%phase(d) = phase_stick
      end do
      st%near = .false.
      st%crossed = .false.
      st%cur = 0
   end subroutine block

   subroutine block_model(slip, model)
      real(dp), intent(in) :: slip(:)
      type(model_type), intent(out) :: model
      integer :: d
      model%n_dof = 1
      model%mass = [m]
      model%u0 = [0.0_dp]
      model%v0 = [0.0_dp]
      model%n_devices = size(slip)
      allocate (model%dev(size(slip)))
      do d = 1, size(slip)
         model%dev(d) = device_type(node_i=1, node_j=0, law=law_coulomb, p=slip(d), mu=1.0_dp)
      end do
      call pairs_of(model)
   end subroutine block_model

   !> Decide at t; the phases and the sticking devices' forces (0 for a sliding one).
   subroutine decide_at(slip, t, phase, force, error)
      real(dp), intent(in) :: slip(:), t
      integer, intent(out) :: phase(size(slip))
      real(dp), intent(out) :: force(size(slip))
      type(error_type), allocatable, intent(out) :: error
      type(ed_state) :: st
      type(excitation_type) :: exc
      type(model_type) :: model
      type(fd_error_type), allocatable :: err
      real(dp) :: xg, vg, ag
      integer :: r
      logical :: changed

      call block(slip, st, exc, error)
      if (allocated(error)) return
      call block_model(slip, model)
      call decide_phases(model, exc, t, st, changed, err)
      if (allocated(err)) then
         call test_failed(error, err%message)
         return
      end if
      phase = st%phase
      force = 0.0_dp
      call table_motion(exc, t, xg, vg, ag)
      associate (pat => st%cache%slot(st%cur))
         do r = 1, pat%ns
            force(pat%ids(r)) = pat%fag(r)*ag + st%f0(r)
         end do
      end associate
   end subroutine decide_at

   real(dp) function ag_at(t)
      real(dp), intent(in) :: t
      type(excitation_type) :: exc
      real(dp) :: xg, vg
      exc%kind = excitation_harmonic
      exc%amplitude = amp
      exc%frequency = freq
      call table_motion(exc, t, xg, vg, ag_at)
   end function ag_at

   !> t = 0.01 s: m |ag| = 0.39 N < P mu = 2 N: it sticks, with F = -m ag.
   subroutine test_sticks(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: phase(1)
      real(dp) :: force(1)
      call decide_at([2.0_dp], 0.01_dp, phase, force, error)
      if (allocated(error)) return
      call check(error, phase(1), phase_stick)
      if (allocated(error)) return
      call check_close(error, force(1), -m*ag_at(0.01_dp), 1e-13_dp, "F = -m ag")
   end subroutine test_sticks

   !> A quarter period (ag = -1.58 m/s2): m |ag| = 3.16 N > 2 N: it slides, the + way (the
   !> inertial force -m ag on the block is positive in the table's frame).
   subroutine test_slides(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: phase(1)
      real(dp) :: force(1)
      call decide_at([2.0_dp], 0.125_dp, phase, force, error)
      if (allocated(error)) return
      call check(error, phase(1), 1)
   end subroutine test_slides

   !> An eighth of a period: the limit is m |ag| exactly, and |ag| grows: it slides.
   subroutine test_limit_growing(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: phase(1)
      real(dp) :: force(1), t
      t = 0.0625_dp
      call decide_at([m*abs(ag_at(t))], t, phase, force, error)
      if (allocated(error)) return
      call check(error, phase(1), 1)
   end subroutine test_limit_growing

   !> Three eighths of a period: the limit is m |ag| exactly, and |ag| falls: it sticks,
   !> at its limit.
   subroutine test_limit_falling(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: phase(1)
      real(dp) :: force(1), t
      t = 0.1875_dp
      call decide_at([m*abs(ag_at(t))], t, phase, force, error)
      if (allocated(error)) return
      call check(error, phase(1), phase_stick)
      if (allocated(error)) return
      call check_close(error, force(1), -m*ag_at(t), 1e-12_dp, "F at its limit")
   end subroutine test_limit_falling

   !> Limits 0.5 N and 1.5 N: at t = 0.01 s (m |ag| = 0.39 N) both stick, F_d in proportion
   !> to the limits and summing to -m ag; at a quarter period (3.16 N > 2 N) both slide.
   subroutine test_parallel(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: phase(2)
      real(dp) :: force(2)
      call decide_at([0.5_dp, 1.5_dp], 0.01_dp, phase, force, error)
      if (allocated(error)) return
      call check(error, all(phase == phase_stick), "both stick")
      if (allocated(error)) return
      call check_close(error, force(1) + force(2), -m*ag_at(0.01_dp), 1e-13_dp, "resultant -m ag")
      if (allocated(error)) return
      call check_close(error, force(2), 3.0_dp*force(1), 1e-13_dp, "shares in proportion")
      if (allocated(error)) return
      call decide_at([0.5_dp, 1.5_dp], 0.125_dp, phase, force, error)
      if (allocated(error)) return
      call check(error, all(phase == 1), "both slide the + way")
   end subroutine test_parallel

end module test_fd_phase_decision
