!> Unit tests of the table motion (fd_excitation): the harmonic motion against its closed
!> form, displacement, velocity and acceleration consistent by central differences with and
!> without the cosine ramp, the ramp starting from rest and ending continuously, and the
!> linear interpolation of a record, with the table at rest after its end; the table
!> acceleration on a time step's grid (grid_motion) against the sine at every point; a second
!> horizontal component's load M r2 for a time-step loop (second_table_motion), refused
!> without the model's direction of it.
module test_fd_excitation
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_excitation, only: excitation_type, table_motion, excitation_none, excitation_harmonic, excitation_record, &
                            table_acceleration, grid_motion, grid_init, grid_acceleration, second_table_motion
   use fd_error, only: fd_error_type => error_type
   use fd_model, only: model_type
   use test_fd_helpers, only: check_close
   implicit none
   private

   public :: collect_excitation

   real(dp), parameter :: pi = acos(-1.0_dp)
   ! the paper's test 4 (Table 1)
   real(dp), parameter :: amp = 0.004052_dp, freq = 4.104_dp

contains

   subroutine collect_excitation(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("harmonic closed form", test_harmonic), &
                  new_unittest("derivatives by differences", test_differences), &
                  new_unittest("ramp starts from rest", test_ramp_start), &
                  new_unittest("ramp ends continuously", test_ramp_end), &
                  new_unittest("record interpolation", test_record), &
                  new_unittest("table at rest", test_none), &
                  new_unittest("grid acceleration against the sine", test_grid), &
                  new_unittest("grid of other motions", test_grid_other), &
                  new_unittest("second component's load", test_second_component) &
                  ]
   end subroutine collect_excitation

   pure function harmonic(ramp_cycles) result(exc)
      integer, intent(in) :: ramp_cycles
      type(excitation_type) :: exc
      exc%kind = excitation_harmonic
      exc%amplitude = amp
      exc%frequency = freq
      exc%ramp_cycles = ramp_cycles
      exc%duration = 40.0_dp
      exc%dt_record = 0.005_dp
   end function harmonic

   !> x0 = a sin(w t), v = a w cos(w t), a = -a w^2 sin(w t) without a ramp.
   subroutine test_harmonic(error)
      type(error_type), allocatable, intent(out) :: error
      type(excitation_type) :: exc
      real(dp) :: t, xg, vg, ag, w
      integer :: i

      exc = harmonic(0)
      w = 2.0_dp*pi*freq
      do i = 0, 20
         t = 0.0137_dp*i
         call table_motion(exc, t, xg, vg, ag)
         call check_close(error, xg, amp*sin(w*t), 1.0e-15_dp*amp, 'harmonic displacement', absolute=.true.)
         if (allocated(error)) return
         call check_close(error, vg, amp*w*cos(w*t), 1.0e-15_dp*amp*w, 'harmonic velocity', absolute=.true.)
         if (allocated(error)) return
         call check_close(error, ag, -amp*w**2*sin(w*t), 1.0e-15_dp*amp*w**2, 'harmonic acceleration', &
                          absolute=.true.)
         if (allocated(error)) return
      end do
   end subroutine test_harmonic

   !> (x(t + h) - x(t - h))/(2 h) = v(t) + O(h^2), and the same for v and a, inside the ramp,
   !> after it and without one. h = 1e-5 s: the truncation error (w h)^2/6 is 1.1e-8 relative,
   !> the round-off eps/(2 w h) 4e-13.
   subroutine test_differences(error)
      type(error_type), allocatable, intent(out) :: error
      type(excitation_type) :: exc
      real(dp), parameter :: h = 1.0e-5_dp
      real(dp) :: t, w, xp, vp, ap, xm, vm, am, x0, v0, a0
      integer :: i, ramp

      w = 2.0_dp*pi*freq
      do ramp = 0, 3, 3
         exc = harmonic(ramp)
         do i = 1, 40
            t = 0.0371_dp*i          ! 0.037 s to 1.48 s: the ramp (3 cycles) ends at 0.731 s
            call table_motion(exc, t + h, xp, vp, ap)
            call table_motion(exc, t - h, xm, vm, am)
            call table_motion(exc, t, x0, v0, a0)
            call check_close(error, (xp - xm)/(2.0_dp*h), v0, 1.0e-7_dp*amp*w, 'v = dx/dt', absolute=.true.)
            if (allocated(error)) return
            call check_close(error, (vp - vm)/(2.0_dp*h), a0, 1.0e-7_dp*amp*w**2, 'a = dv/dt', absolute=.true.)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_differences

   !> R(0) = R'(0) = 0: the ramped table starts at rest, with no acceleration step.
   subroutine test_ramp_start(error)
      type(error_type), allocatable, intent(out) :: error
      type(excitation_type) :: exc
      real(dp) :: xg, vg, ag, w

      exc = harmonic(2)
      call table_motion(exc, 0.0_dp, xg, vg, ag)
      call check(error, xg == 0.0_dp .and. vg == 0.0_dp .and. ag == 0.0_dp, 'at rest at t = 0')
      if (allocated(error)) return
      ! early on a(t) = 1.5 a0 w (pi/tr)^2 t + O(t^2): 2.4e-3 a0 w^2 at 1 ms
      w = 2.0_dp*pi*freq
      call table_motion(exc, 1.0e-3_dp, xg, vg, ag)
      call check(error, abs(ag) < 1.0e-2_dp*amp*w**2, 'no acceleration step at the start')
   end subroutine test_ramp_start

   !> At the end of the ramp (whole cycles, tr = n / f) x, v and a are continuous. Across
   !> tr -+ d, d = 1e-9 s, each changes by d times the sum of its one-sided derivatives, to
   !> round-off: 2 d v and 2 d a for x and v; for a, the jerk jumps (R'' = -(pi/tr)^2/2 at
   !> tr): d (J- + J+) = -d a0 (2 w^3 + 1.5 (pi/tr)^2 w). A step of a at tr would add to it.
   subroutine test_ramp_end(error)
      type(error_type), allocatable, intent(out) :: error
      type(excitation_type) :: exc
      real(dp), parameter :: d = 1.0e-9_dp
      real(dp) :: tr, w, xm, vm, am, xp, vp, ap, x0, v0, a0

      w = 2.0_dp*pi*freq
      exc = harmonic(3)
      tr = 3.0_dp/freq
      call table_motion(exc, tr - d, xm, vm, am)
      call table_motion(exc, tr + d, xp, vp, ap)
      call table_motion(exc, tr, x0, v0, a0)
      call check_close(error, xp - xm, 2.0_dp*d*v0, 1.0e-12_dp*amp, 'x continuous at the end of the ramp', &
                       absolute=.true.)
      if (allocated(error)) return
      call check_close(error, vp - vm, 2.0_dp*d*a0, 1.0e-12_dp*amp*w, 'v continuous at the end of the ramp', &
                       absolute=.true.)
      if (allocated(error)) return
      call check_close(error, ap - am, -d*amp*(2.0_dp*w**3 + 1.5_dp*(pi/tr)**2*w), 1.0e-12_dp*amp*w**2, &
                       'a continuous at the end of the ramp', absolute=.true.)
      if (allocated(error)) return
      ! and after it, the plain harmonic motion
      call table_motion(exc, tr + 0.1_dp, xp, vp, ap)
      call check_close(error, ap, -amp*w**2*sin(w*(tr + 0.1_dp)), 1.0e-14_dp*amp*w**2, 'harmonic after the ramp', &
                       absolute=.true.)
   end subroutine test_ramp_end

   !> Linear between samples, the samples at their times, nothing after the last one
   !> nor before t = 0; only the acceleration is defined.
   subroutine test_record(error)
      type(error_type), allocatable, intent(out) :: error
      type(excitation_type) :: exc
      real(dp) :: xg, vg, ag
      integer :: k

      exc%kind = excitation_record
      exc%dt_record = 0.1_dp
      exc%acc = [0.0_dp, 1.0_dp, 4.0_dp, 9.0_dp]
      do k = 0, 3
         call table_motion(exc, k*0.1_dp, xg, vg, ag)
         call check_close(error, ag, exc%acc(k + 1), 1.0e-14_dp, 'the sample at its time')
         if (allocated(error)) return
      end do
      call table_motion(exc, 0.15_dp, xg, vg, ag)
      call check_close(error, ag, 2.5_dp, 1.0e-14_dp, 'halfway between samples 2 and 3')
      if (allocated(error)) return
      call table_motion(exc, 0.275_dp, xg, vg, ag)
      call check_close(error, ag, 4.0_dp + 0.75_dp*5.0_dp, 1.0e-14_dp, 'three quarters between samples 3 and 4')
      if (allocated(error)) return
      call check(error, xg == 0.0_dp .and. vg == 0.0_dp, 'a record defines the acceleration only')
      if (allocated(error)) return
      call table_motion(exc, 0.3_dp + 1.0e-6_dp, xg, vg, ag)
      call check(error, ag == 0.0_dp, 'at rest after the record')
      if (allocated(error)) return
      call table_motion(exc, 7.0_dp, xg, vg, ag)
      call check(error, ag == 0.0_dp, 'at rest long after the record')
      if (allocated(error)) return
      call table_motion(exc, -0.05_dp, xg, vg, ag)
      call check(error, ag == 0.0_dp, 'at rest before t = 0')
   end subroutine test_record

   subroutine test_none(error)
      type(error_type), allocatable, intent(out) :: error
      type(excitation_type) :: exc
      real(dp) :: xg, vg, ag

      exc%kind = excitation_none
      exc%amplitude = 1.0_dp
      exc%frequency = 1.0_dp
      call table_motion(exc, 0.3_dp, xg, vg, ag)
      call check(error, xg == 0.0_dp .and. vg == 0.0_dp .and. ag == 0.0_dp, 'no excitation: the table at rest')
   end subroutine test_none

   !> Test 4's dt1 grid (h = 0.25 ms) over 100 s, in order, backwards and by jumps: every point
   !> within (8 + 2 w t) ulp of a w^2 of the sine of table_acceleration (both round the
   !> argument w t, whose ulp grows with t; the grid adds one rounding per term). The bound is
   !> reached: the largest difference is asserted above a quarter of it, so the check is
   !> not looser than the grid's error (on this grid it is 0.8 of it).
   subroutine test_grid(error)
      type(error_type), allocatable, intent(out) :: error
      type(excitation_type) :: exc
      type(grid_motion) :: grid
      real(dp), parameter :: h = 0.005_dp/20
      real(dp) :: w, ag, ref, bound, worst
      integer :: k, m, p

      exc = harmonic(0)
      w = 2.0_dp*pi*freq
      call grid_init(exc, h, grid)
      worst = 0.0_dp
      do m = 1, 3
         do k = 0, 400000
            select case (m)
            case (1)
               p = k
            case (2)
               p = 400000 - k
            case default
               p = mod(5003*k, 400001)   ! 5003 * 400000 < 2**31
            end select
            call grid_acceleration(exc, grid, p, p*h, ag)
            ref = table_acceleration(exc, p*h)
            bound = (8.0_dp + 2.0_dp*w*p*h)*epsilon(1.0_dp)*amp*w*w
            if (m == 1) worst = max(worst, abs(ag - ref)/bound)
            call check(error, abs(ag - ref) <= bound, 'grid acceleration off the sine')
            if (allocated(error)) return
         end do
      end do
      call check(error, worst > 0.25_dp, 'the bound of the grid test is loose')
   end subroutine test_grid

   !> A ramp or a record is not tabulated: the grid gives table_acceleration's bits at the
   !> time passed.
   subroutine test_grid_other(error)
      type(error_type), allocatable, intent(out) :: error
      type(excitation_type) :: exc
      type(grid_motion) :: grid
      real(dp), parameter :: h = 0.005_dp/7
      real(dp) :: ag
      integer :: k, c

      do c = 1, 2
         if (c == 1) then
            exc = harmonic(3)
         else
            exc%kind = excitation_record
            exc%dt_record = 0.005_dp
            exc%acc = [(sin(0.3_dp*k), k=0, 99)]
         end if
         call grid_init(exc, h, grid)
         do k = 0, 200
            call grid_acceleration(exc, grid, k, k*h, ag)
            call check(error, ag == table_acceleration(exc, k*h), 'grid of a ramp or a record')
            if (allocated(error)) return
         end do
      end do
   end subroutine test_grid_other

   !> A second component moves the table only when given and not of kind none; then its load
   !> is M r2 (the model's influence2), and a model without influence2, or one the technique
   !> does not take, is refused with a message naming what gives the direction.
   subroutine test_second_component(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc2, copy, rest
      type(fd_error_type), allocatable :: err
      real(dp), allocatable :: mr2(:)
      logical :: on

      model%n_dof = 3
      model%mass = [2.0_dp, 3.0_dp, 5.0_dp]
      exc2 = harmonic(0)
      call second_table_motion(model, .true., on, copy, mr2, err)
      call check(error, .not. on .and. .not. allocated(err), 'no second component given: none')
      if (allocated(error)) return
      call second_table_motion(model, .true., on, copy, mr2, err, rest)
      call check(error, .not. on .and. .not. allocated(err), 'a second component at rest: none')
      if (allocated(error)) return
      call second_table_motion(model, .true., on, copy, mr2, err, exc2)
      call check(error, .not. on .and. allocated(err), 'no influence2: refused')
      if (allocated(error)) return
      call check(error, index(err%message, "&floors, or influence2 of &matrices") > 0, err%message)
      if (allocated(error)) return
      model%influence2 = [0.0_dp, 1.0_dp, -0.5_dp]
      call second_table_motion(model, .false., on, copy, mr2, err, exc2)
      call check(error, .not. on .and. allocated(err), 'a direction the technique does not take: refused')
      if (allocated(error)) return
      call second_table_motion(model, .true., on, copy, mr2, err, exc2)
      call check(error, on .and. .not. allocated(err) .and. copy%kind == excitation_harmonic, 'taken')
      if (allocated(error)) return
      call check(error, all(mr2 == [0.0_dp, 3.0_dp, -2.5_dp]), 'its load M r2')
   end subroutine test_second_component

end module test_fd_excitation
