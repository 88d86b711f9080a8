!> Elastic vertical supports (fd_vertical_support) against closed forms: the step response of
!> the oscillator, the lift-off time and free flight under a downward acceleration beyond g, the
!> energy of an undamped support through a flight, and the normal forces handed to the laws.
module test_fd_vertical_support
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use test_fd_helpers, only: check_close
   use fd_kinds, only: dp
   use fd_model, only: device_type
   use fd_vertical_support, only: vertical_support, support_setup, support_advance, support_accept, &
                                  support_forces, support_normal_force, support_energy
   implicit none
   private

   public :: collect_vertical_support

   real(dp), parameter :: pi = 3.14159265358979323846_dp
   real(dp), parameter :: g = 9.80665_dp
   real(dp), parameter :: m = 1000.0_dp             !! the bearing's share of the mass [kg]
   real(dp), parameter :: tv = 0.05_dp              !! vertical period [s]

contains

   subroutine collect_vertical_support(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("step response: closed form", test_step), &
                  new_unittest("lift-off and free flight: closed form", test_flight), &
                  new_unittest("undamped energy through a flight", test_energy), &
                  new_unittest("normal forces to the laws", test_forces) &
                  ]
   end subroutine collect_vertical_support

   !> One bearing (devices 1, 2: its x and y components) on a support of period tv, damping zeta.
   subroutine one_bearing(zeta, vs)
      real(dp), intent(in) :: zeta
      type(vertical_support), intent(out) :: vs
      type(device_type) :: dev(3)
      integer :: stat

      dev(1)%partner = 2
      dev(1)%component = 1
      dev(2)%partner = 1
      dev(2)%component = 2
      dev(1:2)%p_static = m*g
      dev(1:2)%p = m*g
      dev(1:2)%kv = m*(2.0_dp*pi/tv)**2
      dev(1:2)%zeta_v = zeta
      dev(3)%p = 5.0_dp                      ! a one-dimensional device: no support
      call support_setup(3, dev, 2, vs, stat)
      if (stat /= 0) error stop "support_setup: no memory"
   end subroutine one_bearing

   !> A constant a_z = a (upward, from rest): z = (a / wn^2) (1 - cos wn t), N = m g + kv z; steps
   !> of two sizes alternating (each slot keeps its map).
   subroutine test_step(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: a = 0.4_dp*g
      type(vertical_support) :: vs
      real(dp) :: t, h, wn, z
      integer :: k

      call one_bearing(0.0_dp, vs)
      call check(error, vs%nb, 1)
      if (allocated(error)) return
      wn = 2.0_dp*pi/tv
      t = 0.0_dp
      do k = 1, 60
         h = merge(1.3e-3_dp, 0.7e-3_dp, mod(k, 3) == 0)
         call support_advance(vs, merge(1, 2, mod(k, 3) == 0), t + h, a, a)
         call support_accept(vs)
         t = t + h
      end do
      z = a/wn**2*(1.0_dp - cos(wn*t))
      call check_close(error, vs%z(1), z, 1.0e-11_dp, "z")
      if (allocated(error)) return
      call check_close(error, support_normal_force(vs, 1, .false.), m*g + m*wn**2*z, 1.0e-13_dp, "N")
   end subroutine test_step

   !> a_z = -1.5 g from rest: z = -(a / wn^2)(1 - cos wn t) reaches the spring's free end
   !> -g / wn^2 at cos wn tL = 1 - g / a; then z'' = g - a: it keeps rising. Over steps of 1 ms the
   !> lift-off is located within one.
   subroutine test_flight(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: a = 1.5_dp*g, h = 1.0e-3_dp
      type(vertical_support) :: vs
      real(dp) :: tl, wn, t, zl, vl, s, z
      integer :: k

      call one_bearing(0.0_dp, vs)
      wn = 2.0_dp*pi/tv
      tl = acos(1.0_dp - g/a)/wn
      t = 0.0_dp
      do k = 1, 30
         call support_advance(vs, 1, t + h, -a, -a)
         call support_accept(vs)
         t = t + h
      end do
      call check(error, vs%flights(1), 1)
      if (allocated(error)) return
      call check_close(error, vs%first(1), tl, 1.0e-12_dp, "lift-off time")
      if (allocated(error)) return
      call check_close(error, vs%air(1), t - tl, 1.0e-11_dp, "time in flight")
      if (allocated(error)) return
      zl = -g/wn**2
      vl = -(a/wn)*sin(wn*tl)
      s = t - tl
      z = zl + vl*s + 0.5_dp*(g - a)*s*s
      call check_close(error, vs%z(1), z, 1.0e-11_dp, "z in flight")
      if (allocated(error)) return
      call check_close(error, vs%gap(1), -(z - zl), 1.0e-10_dp, "peak uplift")
      if (allocated(error)) return
      call check(error, support_normal_force(vs, 1, .false.) == 0.0_dp, "no force in flight")
   end subroutine test_flight

   !> Undamped, through lift-offs and landings (a pulse of -1.5 g, then 0): the ground's work
   !> equals the change of the support's energy to round-off.
   subroutine test_energy(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), parameter :: h = 1.0e-3_dp
      type(vertical_support) :: vs
      real(dp) :: t, a0, a1, w, ek, ep, scale
      integer :: k

      call one_bearing(0.0_dp, vs)
      t = 0.0_dp
      w = 0.0_dp
      scale = 0.0_dp
      do k = 1, 400
         a0 = merge(-1.5_dp*g, 0.0_dp, k <= 20)
         a1 = merge(-1.5_dp*g, 0.0_dp, k < 20)
         call support_advance(vs, 1, t + h, a0, a1)
         call support_accept(vs)
         w = w + vs%w_in1
         scale = scale + abs(vs%w_in1)
         t = t + h
      end do
      call check(error, vs%flights(1) >= 2, "lifted off, landed and lifted off again")
      if (allocated(error)) return
      call support_energy(vs, ek, ep)
      call check(error, abs(w - (ek + ep)) < 1.0e-12_dp*scale, "work = energy")
   end subroutine test_energy

   !> The laws' p: the accepted N, the trial's and a theta mix of them, plus a dN; 0 in flight.
   subroutine test_forces(error)
      type(error_type), allocatable, intent(out) :: error
      type(vertical_support) :: vs
      type(device_type) :: dev(3)
      real(dp) :: n0, n1

      call one_bearing(0.02_dp, vs)
      dev(1:2)%p = m*g
      dev(3)%p = 5.0_dp
      call support_advance(vs, 1, 1.0e-2_dp, 0.0_dp, 0.3_dp*g)
      n0 = support_normal_force(vs, 1, .false.)
      n1 = support_normal_force(vs, 1, .true.)
      call check_close(error, n0, m*g, 1.0e-15_dp, "at rest")
      if (allocated(error)) return
      call check(error, n1 > m*g, "pressed harder")
      if (allocated(error)) return
      call support_forces(vs, 0.5_dp, 3, dev, [100.0_dp])
      call check_close(error, dev(1)%p, 0.5_dp*(n0 + n1) + 100.0_dp, 1.0e-15_dp, "theta point")
      if (allocated(error)) return
      call check(error, dev(2)%p == dev(1)%p .and. dev(3)%p == 5.0_dp, "both components, not the others")
      if (allocated(error)) return
      call support_accept(vs)
      vs%fly = .true.
      call support_forces(vs, 0.0_dp, 3, dev, [100.0_dp])
      call check(error, dev(1)%p == 0.0_dp, "no force in flight, whatever dN")
   end subroutine test_forces

end module test_fd_vertical_support
