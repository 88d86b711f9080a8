!> Unit tests of the reduced system of a phase pattern, its closed form between events
!> (Taylor polynomial and remainder bound) and its force map (fd_phase_pattern) against
!> closed forms: a free damped oscillator, a rigid body under a constant (sliding friction)
!> force, an undamped oscillator under harmonic table motion, a free mass under a
!> piecewise-linear record, a mass stuck to the table, the force that keeps two masses
!> together, devices in parallel sharing their load in proportion to their limits, and the
!> cache.
module test_fd_phase_pattern
   use testdrive, only: new_unittest, unittest_type, error_type, check, test_failed
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_model, only: model_type, device_type, law_coulomb
   use fd_excitation, only: excitation_type, excitation_none, excitation_harmonic, excitation_record, &
                            table_taylor
   use fd_phase_pattern, only: pattern_type, pattern_cache, cache_init, cache_find, build_pattern, &
                               pattern_entry, pattern_taylor, remainder_bound, kmax, null_space_basis
   use fd_kinematics, only: append_device
   use fd_taylor, only: poly_value
   use test_fd_helpers, only: check_close, pairs_of
   implicit none
   private

   public :: collect_phase_pattern

   real(dp), parameter :: pi = acos(-1.0_dp)

   !> A pattern entered at a state, with its Taylor coefficients about t.
   type :: entered
      type(pattern_type) :: pat
      real(dp), allocatable :: q(:), p(:), uc(:), b1(:), f0(:), u(:), v(:)
      real(dp) :: qc(4, 0:kmax + 1), pc(4, 0:kmax + 1), cp(4, 0:kmax + 1), g(0:kmax), gn(0:kmax)
   end type entered

contains

   subroutine collect_phase_pattern(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("free damped oscillator", test_damped_oscillator), &
                  new_unittest("rigid body under a constant force", test_sliding_block), &
                  new_unittest("harmonic table motion", test_harmonic), &
                  new_unittest("record (linear between samples)", test_record), &
                  new_unittest("mass stuck to the table", test_stuck_to_table), &
                  new_unittest("force that keeps two masses together", test_two_masses), &
                  new_unittest("devices in parallel share in proportion", test_parallel), &
                  new_unittest("cache: one build per pattern", test_cache), &
                  new_unittest("null space basis of a general direction", test_null_space), &
                  new_unittest("general pattern: the two masses' force", test_general_two_masses) &
                  ]
   end subroutine collect_phase_pattern

   !> n masses; devices given by node pairs with limits slip (P = slip, mu = 1).
   subroutine make_model(mass, ni, nj, slip, model)
      real(dp), intent(in) :: mass(:)
      integer, intent(in) :: ni(:), nj(:)
      real(dp), intent(in) :: slip(:)
      type(model_type), intent(out) :: model
      integer :: d

      model%n_dof = size(mass)
      model%mass = mass
      allocate (model%u0(size(mass)), model%v0(size(mass)))
      model%u0 = 0.0_dp
      model%v0 = 0.0_dp
      model%n_devices = size(ni)
      allocate (model%dev(size(ni)))
      do d = 1, size(ni)
         model%dev(d) = device_type(node_i=ni(d), node_j=nj(d), law=law_coulomb, p=slip(d), mu=1.0_dp)
      end do
      call pairs_of(model)
   end subroutine make_model

   !> Build the pattern of the phases, enter it at (u, v) and expand it about t.
   subroutine enter_at(model, k, c, phase, exc, t, u, v, e, error)
      type(model_type), intent(in) :: model
      real(dp), intent(in) :: k(:, :), c(:, :)
      integer, intent(in) :: phase(:)
      type(excitation_type), intent(in) :: exc
      real(dp), intent(in) :: t, u(:), v(:)
      type(entered), intent(inout) :: e
      type(error_type), allocatable, intent(out) :: error
      type(fd_error_type), allocatable :: err
      real(dp) :: slip(size(phase)), fn(size(u))
      logical :: active(size(phase))
      integer :: d, n

      n = size(u)
      do d = 1, size(phase)
         slip(d) = model%dev(d)%p*model%dev(d)%mu
      end do
      active = slip > 0.0_dp
      call build_pattern(model, model%mass, k, c, active, phase, slip, exc, e%pat, err)
      if (allocated(err)) then
         call test_failed(error, err%message)
         return
      end if
      allocate (e%q(n), e%p(n), e%uc(n), e%b1(n), e%f0(max(1, size(phase))))
      e%u = u
      e%v = v
      call pattern_entry(e%pat, model, model%mass, k, phase, slip, e%u, e%v, e%q, e%p, e%uc, e%b1, e%f0, fn)
      call table_taylor(exc, t, e%g(0:e%pat%order), e%gn(0:e%pat%order))
      call pattern_taylor(e%pat, e%q, e%p, e%b1, e%g(0:e%pat%order), e%qc, e%pc, e%cp)
   end subroutine enter_at

   !> q(s), p(s) of group 1 from the coefficients, and the remainder bound of u over s.
   subroutine state_at(e, s, u, v, bound)
      type(entered), intent(in) :: e
      real(dp), intent(in) :: s
      real(dp), intent(out) :: u, v, bound
      u = poly_value(e%qc(1, 0:e%pat%order), s)
      v = poly_value(e%pc(1, 0:e%pat%order), s)
      bound = e%pat%wq(1)*remainder_bound(e%pat, e%qc, e%pc, e%gn(e%pat%order), s)
   end subroutine state_at

   !> m u'' + c u' + k u = 0 over one sub-interval: the closed form
   !> u = e^(-z w t) (u0 cos wd t + (v0 + z w u0)/wd sin wd t) to 1e-14 of the amplitude,
   !> and the remainder bound both above the actual error and below 1e-15 of it.
   subroutine test_damped_oscillator(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(entered) :: e
      real(dp) :: m, k, c, w, z, wd, u0, v0, s, ex, u, v, ue, ve, amp, bound, kk(1, 1), cc(1, 1)
      integer :: i, no_phase(0)

      m = 2.0_dp; k = 800.0_dp; z = 0.05_dp
      w = sqrt(k/m); c = 2.0_dp*z*w*m; wd = w*sqrt(1.0_dp - z*z)
      u0 = 0.01_dp; v0 = -0.3_dp
      call make_model([m], [integer ::], [integer ::], [real(dp) ::], model)
      exc%kind = excitation_none
      kk = k; cc = c
      call enter_at(model, kk, cc, no_phase, exc, 0.0_dp, [u0], [v0], e, error)
      if (allocated(error)) return
      call check(error, e%pat%nq, 1)
      if (allocated(error)) return
      amp = sqrt(u0**2 + ((v0 + z*w*u0)/wd)**2)
      do i = 0, 10
         s = e%pat%delta*i/10.0_dp
         ex = exp(-z*w*s)
         ue = ex*(u0*cos(wd*s) + (v0 + z*w*u0)/wd*sin(wd*s))
         ve = ex*(v0*cos(wd*s) - (w*w*u0 + z*w*v0)/wd*sin(wd*s))
         call state_at(e, s, u, v, bound)
         call check_close(error, u, ue, 1.0e-14_dp*amp, "damped oscillator u", absolute=.true.)
         if (allocated(error)) return
         call check_close(error, v, ve, 1.0e-14_dp*amp*w, "damped oscillator v", absolute=.true.)
         if (allocated(error)) return
         call check(error, bound <= 1.0e-15_dp*amp, "remainder bound above the rounding level")
         if (allocated(error)) return
      end do
   end subroutine test_damped_oscillator

   !> A block sliding (phase +1) on the table, no spring (a rigid-body mode: A defective):
   !> u = u0 + v0 t - P mu t^2 / (2 m) exactly, the remainder bound 0.
   subroutine test_sliding_block(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(entered) :: e
      real(dp) :: m, a, u0, v0, s, u, v, bound, kk(1, 1), cc(1, 1)

      m = 2.0_dp; u0 = 0.003_dp; v0 = 0.8_dp; s = 0.21_dp
      a = 5.0_dp/m
      call make_model([m], [1], [0], [5.0_dp], model)
      exc%kind = excitation_none
      kk = 0.0_dp; cc = 0.0_dp
      call enter_at(model, kk, cc, [1], exc, 0.0_dp, [u0], [v0], e, error)
      if (allocated(error)) return
      call check(error, e%pat%nq, 1)
      if (allocated(error)) return
      call state_at(e, s, u, v, bound)
      call check_close(error, u, u0 + v0*s - 0.5_dp*a*s**2, 4.0_dp*epsilon(1.0_dp), "sliding block u")
      if (allocated(error)) return
      call check_close(error, v, v0 - a*s, 4.0_dp*epsilon(1.0_dp), "sliding block v")
      if (allocated(error)) return
      call check(error, bound == 0.0_dp, "the quadratic is exact: no remainder")
   end subroutine test_sliding_block

   !> u'' + w0^2 u = a0 w^2 sin(w t) from the closed-form state at t1 = 0.35 s:
   !> u = a0 w^2 / (w0^2 - w^2) (sin w t - (w / w0) sin w0 t) to 1e-14 of the amplitude.
   subroutine test_harmonic(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(entered) :: e
      real(dp) :: w0, w, a0, amp, t1, s, u, v, bound, kk(1, 1), cc(1, 1)
      integer :: i, no_phase(0)

      w0 = 10.0_dp
      exc%kind = excitation_harmonic
      exc%amplitude = 0.01_dp
      exc%frequency = 1.0_dp
      exc%ramp_cycles = 0
      a0 = exc%amplitude; w = 2.0_dp*pi*exc%frequency
      amp = a0*w*w/(w0*w0 - w*w)*(1.0_dp + w/w0)
      call make_model([1.0_dp], [integer ::], [integer ::], [real(dp) ::], model)
      kk = w0*w0; cc = 0.0_dp
      t1 = 0.35_dp
      call enter_at(model, kk, cc, no_phase, exc, t1, [u_exact(t1)], [v_exact(t1)], e, error)
      if (allocated(error)) return
      do i = 0, 8
         s = e%pat%delta*i/8.0_dp
         call state_at(e, s, u, v, bound)
         call check_close(error, u, u_exact(t1 + s), 1.0e-14_dp*amp, "harmonic u", absolute=.true.)
         if (allocated(error)) return
         call check_close(error, v, v_exact(t1 + s), 1.0e-14_dp*amp*w0, "harmonic v", absolute=.true.)
         if (allocated(error)) return
         call check(error, bound <= 1.0e-15_dp*amp, "remainder bound above the rounding level")
         if (allocated(error)) return
      end do
   contains
      real(dp) function u_exact(t)
         real(dp), intent(in) :: t
         u_exact = a0*w*w/(w0*w0 - w*w)*(sin(w*t) - w/w0*sin(w0*t))
      end function u_exact
      real(dp) function v_exact(t)
         real(dp), intent(in) :: t
         v_exact = a0*w*w/(w0*w0 - w*w)*(w*cos(w*t) - w*cos(w0*t))
      end function v_exact
   end subroutine test_harmonic

   !> A free mass under a record, linear between samples: u'' = -(g0 + g1 t), so
   !> u = u0 + v0 t - g0 t^2 / 2 - g1 t^3 / 6, from a time inside the first interval.
   subroutine test_record(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(entered) :: e
      real(dp) :: g0, g1, u0, v0, s, u, v, bound, kk(1, 1), cc(1, 1), t0
      integer :: no_phase(0)

      exc%kind = excitation_record
      exc%dt_record = 0.1_dp
      exc%acc = [1.5_dp, -0.5_dp, 7.0_dp]
      t0 = 0.04_dp
      g1 = -20.0_dp
      g0 = 1.5_dp + g1*t0
      u0 = 0.002_dp; v0 = 0.05_dp
      call make_model([3.0_dp], [integer ::], [integer ::], [real(dp) ::], model)
      kk = 0.0_dp; cc = 0.0_dp
      call enter_at(model, kk, cc, no_phase, exc, t0, [u0], [v0], e, error)
      if (allocated(error)) return
      s = 0.06_dp
      call state_at(e, s, u, v, bound)
      call check_close(error, u, u0 + v0*s - g0*s**2/2.0_dp - g1*s**3/6.0_dp, 1.0e-15_dp, "record u")
      if (allocated(error)) return
      call check_close(error, v, v0 - g0*s - g1*s**2/2.0_dp, 1.0e-15_dp, "record v")
      if (allocated(error)) return
      call check(error, bound == 0.0_dp, "the cubic is exact: no remainder")
   end subroutine test_record

   !> A sticking device to the table links the mass to it: no reduced DOF; the device
   !> carries F = -m ag (the table drags the mass): fag = -m, and the velocity is projected.
   subroutine test_stuck_to_table(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(entered) :: e
      real(dp) :: kk(1, 1), cc(1, 1)

      exc%kind = excitation_harmonic
      exc%amplitude = 0.01_dp
      exc%frequency = 2.0_dp
      call make_model([2.0_dp], [1], [0], [5.0_dp], model)
      kk = 100.0_dp; cc = 1.0_dp
      call enter_at(model, kk, cc, [0], exc, 0.3_dp, [0.004_dp], [1.0e-12_dp], e, error)
      if (allocated(error)) return
      call check(error, e%pat%nq == 0 .and. e%pat%ns == 1, "stuck to the table: no reduced DOF")
      if (allocated(error)) return
      call check(error, e%uc(1) == 0.004_dp .and. e%v(1) == 0.0_dp, "offset kept, velocity projected")
      if (allocated(error)) return
      call check_close(error, e%pat%fag(1), -2.0_dp, 1e-15_dp, "F = -m ag")
      if (allocated(error)) return
      ! and the spring's force on the offset: F = -k u - m ag
      call check_close(error, e%f0(1), -100.0_dp*0.004_dp, 1e-15_dp, "F0 = -k u")
   end subroutine test_stuck_to_table

   !> Two masses on springs to the table, held together by a sticking device (the paper's
   !> model, stuck): from m1's equation, F = -(m1 aabs + k1 u + c1 v), aabs = -(k1 + k2) u/(m1 + m2)
   !> (damping c = psi K).
   subroutine test_two_masses(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(entered) :: e
      real(dp) :: k(2, 2), c(2, 2), m1, m2, k1, k2, psi, u, v, aabs, f, ag
      integer :: i

      m1 = 6.301_dp; m2 = 2.53_dp; k1 = 1084.0_dp; k2 = 2895.0_dp; psi = 1.4e-3_dp
      call make_model([m1, m2], [1], [2], [61.81_dp*0.22_dp], model)
      k = 0.0_dp
      k(1, 1) = k1; k(2, 2) = k2
      c = psi*k
      exc%kind = excitation_harmonic
      exc%amplitude = 0.004052_dp
      exc%frequency = 4.104_dp
      u = 0.003_dp; v = -0.05_dp
      call enter_at(model, k, c, [0], exc, 0.1_dp, [u, u], [v, v], e, error)
      if (allocated(error)) return
      call check(error, e%pat%nq == 1 .and. e%pat%ns == 1, "one group, one sticking device")
      if (allocated(error)) return
      ag = e%g(0)
      aabs = -((k1 + k2)*u + psi*(k1 + k2)*v)/(m1 + m2)
      f = -(m1*aabs + k1*u + psi*k1*v)
      do i = 1, 1
         call check_close(error, e%pat%fq(1, 1)*e%q(1) + e%pat%fp(1, 1)*e%p(1) + e%pat%fag(1)*ag + e%f0(1), f, &
                          1e-13_dp, "force that keeps the masses together")
         if (allocated(error)) return
      end do
   end subroutine test_two_masses

   !> Two devices in parallel between a mass and the table, limits 1 and 3: the force
   !> -m ag is shared 1 : 3 (they reach their limits together).
   subroutine test_parallel(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(entered) :: e
      real(dp) :: kk(1, 1), cc(1, 1)

      exc%kind = excitation_harmonic
      exc%amplitude = 0.01_dp
      exc%frequency = 2.0_dp
      call make_model([2.0_dp], [1, 1], [0, 0], [1.0_dp, 3.0_dp], model)
      kk = 0.0_dp; cc = 0.0_dp
      call enter_at(model, kk, cc, [0, 0], exc, 0.3_dp, [0.0_dp], [0.0_dp], e, error)
      if (allocated(error)) return
      call check_close(error, e%pat%fag(1), -0.5_dp, 1e-14_dp, "share of the limit-1 device")
      if (allocated(error)) return
      call check_close(error, e%pat%fag(2), -1.5_dp, 1e-14_dp, "share of the limit-3 device")
   end subroutine test_parallel

   !> The cache builds a pattern once and finds it again; a new one gets a new slot.
   subroutine test_cache(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(pattern_cache) :: cache
      type(fd_error_type), allocatable :: err
      real(dp) :: k(2, 2), c(2, 2)
      integer :: s1, s2, s3

      call make_model([1.0_dp, 2.0_dp], [1, 2], [0, 1], [1.0_dp, 1.0_dp], model)
      k = 0.0_dp; k(1, 1) = 10.0_dp; k(2, 2) = 5.0_dp
      c = 0.0_dp
      exc%kind = excitation_none
      call cache_init(cache, 2, 2, err)
      call check(error, .not. allocated(err), "cache_init")
      if (allocated(error)) return
      call cache_find(cache, model, model%mass, k, c, [.true., .true.], [0, 1], [1.0_dp, 1.0_dp], exc, [0], s1, err)
      call cache_find(cache, model, model%mass, k, c, [.true., .true.], [1, -1], [1.0_dp, 1.0_dp], exc, [0], s2, err)
      call cache_find(cache, model, model%mass, k, c, [.true., .true.], [0, 1], [1.0_dp, 1.0_dp], exc, [0], s3, err)
      call check(error, .not. allocated(err), "cache_find")
      if (allocated(error)) return
      call check(error, s1 == s3 .and. s1 /= s2 .and. cache%builds == 2, "one build per pattern")
   end subroutine test_cache

   !> Three masses (2, 1, 3), a device of direction b = (1, -0.5, 0.25) linked: the basis T
   !> has two columns, T'MT = I and b'T = 0 (to round-off).
   subroutine test_null_space(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(fd_error_type), allocatable :: err
      real(dp), allocatable :: tm(:, :)
      real(dp) :: mt(2, 2), bt(2)
      integer :: nq, stat, i

      call make_model([2.0_dp, 1.0_dp, 3.0_dp], [integer ::], [integer ::], [real(dp) ::], model)
      call append_device(model, device_type(law=law_coulomb, p=1.0_dp, mu=1.0_dp), [1, 2, 3], &
                         [1.0_dp, -0.5_dp, 0.25_dp], stat)
      call null_space_basis(model, model%mass, [.true.], tm, nq, err)
      call check(error, .not. allocated(err) .and. nq == 2, "two free coordinates")
      if (allocated(error)) return
      mt = matmul(transpose(tm), matmul(reshape([2.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, &
                                                 3.0_dp], [3, 3]), tm))
      bt = matmul([1.0_dp, -0.5_dp, 0.25_dp], tm)
      call check(error, abs(mt(1, 1) - 1.0_dp) + abs(mt(2, 2) - 1.0_dp) + abs(mt(1, 2)) + abs(mt(2, 1)) <= 1e-14_dp, &
                 "T'MT = I")
      if (allocated(error)) return
      do i = 1, 2
         call check(error, abs(bt(i)) <= 1e-14_dp, "b'T = 0")
         if (allocated(error)) return
      end do
   end subroutine test_null_space

   !> The two masses of test_two_masses with the table motion's direction r = (1, 1) given:
   !> the general pattern (T over the null space of b, Mq = I, lq = T'M r) gives the closed
   !> form of the force that keeps them together, and u = T q + uc.
   subroutine test_general_two_masses(error)
      type(error_type), allocatable, intent(out) :: error
      type(model_type) :: model
      type(excitation_type) :: exc
      type(entered) :: e
      real(dp) :: k(2, 2), c(2, 2), m1, m2, k1, k2, psi, u, v, aabs, f

      m1 = 6.301_dp; m2 = 2.53_dp; k1 = 1084.0_dp; k2 = 2895.0_dp; psi = 1.4e-3_dp
      call make_model([m1, m2], [1], [2], [61.81_dp*0.22_dp], model)
      model%influence = [1.0_dp, 1.0_dp]
      k = 0.0_dp
      k(1, 1) = k1; k(2, 2) = k2
      c = psi*k
      exc%kind = excitation_harmonic
      exc%amplitude = 0.004052_dp
      exc%frequency = 4.104_dp
      u = 0.003_dp; v = -0.05_dp
      call enter_at(model, k, c, [0], exc, 0.1_dp, [u, u], [v, v], e, error)
      if (allocated(error)) return
      call check(error, e%pat%general .and. e%pat%nq == 1 .and. e%pat%ns == 1, "general, one coordinate")
      if (allocated(error)) return
      aabs = -((k1 + k2)*u + psi*(k1 + k2)*v)/(m1 + m2)
      f = -(m1*aabs + k1*u + psi*k1*v)
      call check_close(error, e%pat%fq(1, 1)*e%q(1) + e%pat%fp(1, 1)*e%p(1) + e%pat%fag(1)*e%g(0) + e%f0(1), f, &
                       1e-13_dp, "force that keeps the masses together")
      if (allocated(error)) return
      call check_close(error, e%pat%tm(2, 1)*e%q(1) + e%uc(2), u, 1e-14_dp, "u = T q + uc")
   end subroutine test_general_two_masses

end module test_fd_phase_pattern
