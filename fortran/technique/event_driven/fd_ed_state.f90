!> The state of the exact event-driven technique: the structure's matrices, the full state
!> (u, v) at the current instant, the devices' phases, the cache of phase patterns and
!> the current pattern's entry data, and every work array, sized once (ed_setup) so that
!> the loop allocates nothing (a pattern allocates only when it is first built).
!>
!> On a sub-interval [0, S] from the current instant (ed_polynomials) it holds the Taylor
!> polynomials of every output quantity (per DOF u, v, absolute acceleration; per device
!> s and F) and of every event function (per device two: a sliding device's sgn s', and
!> nothing; a sticking device's P mu - F and P mu + F), each with the bound of its
!> remainder and its rounding level eta.
module fd_ed_state
   use fd_kinds, only: dp
   use fd_error, only: error_type, fmt_int, allocation_error
   use fd_model, only: model_type
   use fd_kinematics, only: pair_nodes, device_relative
   use fd_stiffness, only: influence_of
   use fd_excitation, only: excitation_type, table_taylor
   use fd_device_state, only: phase_stick
   use fd_lcp, only: lcp_work, lcp_init
   use fd_taylor, only: poly_abs_bound, max_depth
   use fd_phase_pattern, only: pattern_type, pattern_cache, cache_init, pattern_series, kmax
   implicit none
   private

   public :: ed_state, ed_setup, ed_polynomials, nq_of, iq_u, iq_v, iq_a, iq_s, iq_f

   !> State of the exact technique.
   type :: ed_state
      integer :: n = 0, nd = 0, nquant = 0                !! DOFs, devices, output quantities
      integer :: nbase = 0                                 !! quantities of the state (3 n + 2 nd); the
                                                           !! others (storeys) are the caller's
      real(dp), allocatable :: mass(:), k(:, :), c(:, :)   !! structure
      real(dp), allocatable :: rinf(:)                     !! the table motion's direction r (n)
      real(dp), allocatable :: slip(:)                     !! P mu
      logical, allocatable :: active(:)                    !! P mu > 0
      real(dp), allocatable :: u(:), v(:)                  !! full state at the current instant
      integer, allocatable :: phase(:)                     !! 0 stick, +-1 slide
      type(pattern_cache) :: cache                         !! the patterns met
      integer :: cur = 0                                   !! slot of the current pattern
      ! entry data of the current pattern
      real(dp), allocatable :: q(:), p(:)                  !! reduced state (nq used of n)
      real(dp), allocatable :: uc(:), b1(:), f0(:)         !! offsets (n), load (nq), force constants (ns)
      ! polynomials on the current sub-interval
      real(dp), allocatable :: qc(:, :), pc(:, :), cp(:, :) !! Taylor coefficients (n, 0:kmax+1)
      real(dp), allocatable :: g(:), gn(:)                 !! table acceleration, remainder factors (0:kmax)
      real(dp) :: rem = 0.0_dp                             !! remainder bound of the state's norm
      real(dp) :: size = 0.0_dp                            !! the state polynomial's size
      real(dp) :: grem = 0.0_dp                            !! remainder bound of the table acceleration
      real(dp) :: gsize = 0.0_dp                           !! the table acceleration polynomial's size
      integer :: order = 2                                 !! Taylor degree K of the sub-interval
      real(dp) :: span = 0.0_dp                            !! sub-interval length S
      real(dp), allocatable :: yc(:, :)                    !! quantities (0:kmax, nquant)
      real(dp), allocatable :: yrem(:)                     !! their remainder bounds
      real(dp), allocatable :: ec(:, :)                    !! event functions (0:kmax, 2 nd)
      real(dp), allocatable :: erem(:), eta(:)             !! remainder bounds, rounding levels
      real(dp), allocatable :: offs(:)                     !! value below 0 accepted at the last decision
      logical, allocatable :: eon(:)                       !! event function in use
      ! polynomial kernels' work
      real(dp), allocatable :: pw(:, :), pw2(:), pc1(:), roots(:)
      ! complementarity problems of the phase decision
      type(lcp_work) :: lcp
      real(dp), allocatable :: wm(:, :), lq(:), lqa(:), lo(:), hi(:), z(:), w(:), zs(:)
      integer, allocatable :: cand(:), sig(:), newph(:), oldph(:)
      logical, allocatable :: crossed(:), near(:)
      ! vectors over the DOFs and over the devices
      real(dp), allocatable :: fn(:), pe(:), pa(:), qa(:, :), pq(:, :)
      real(dp), allocatable :: aab(:)                      !! magnitude of the terms of each group's acceleration
   end type ed_state

contains

   !> Number of output quantities: u, v, aabs per DOF, s, F per device.
   pure integer function nq_of(n, nd)
      integer, intent(in) :: n, nd
      nq_of = 3*n + 2*nd
   end function nq_of

   !> Index of u_i, v_i, aabs_i, s_d, F_d among the output quantities.
   pure integer function iq_u(i)
      integer, intent(in) :: i
      iq_u = 3*i - 2
   end function iq_u
   pure integer function iq_v(i)
      integer, intent(in) :: i
      iq_v = 3*i - 1
   end function iq_v
   pure integer function iq_a(i)
      integer, intent(in) :: i
      iq_a = 3*i
   end function iq_a
   pure integer function iq_s(n, d)
      integer, intent(in) :: n, d
      iq_s = 3*n + 2*d - 1
   end function iq_s
   pure integer function iq_f(n, d)
      integer, intent(in) :: n, d
      iq_f = 3*n + 2*d
   end function iq_f

   !> Allocate the state of a model: matrices, work arrays, the pattern cache and the
   !> complementarity solver's workspace.
   subroutine ed_setup(model, st, extra, error)
      type(model_type), intent(in) :: model         !! the model
      type(ed_state), intent(inout) :: st           !! the state
      integer, intent(in) :: extra                  !! output quantities the caller appends
                                                    !! (linear combinations it fills in yc)
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      integer :: n, nd, d, stat, nqt

      n = model%n_dof
      nd = model%n_devices
      st%n = n
      st%nd = nd
      st%nbase = nq_of(n, nd)
      nqt = st%nbase + extra
      st%nquant = nqt
      allocate (st%mass(n), st%rinf(n), st%k(n, n), st%c(n, n), st%slip(nd), st%active(nd), st%u(n), st%v(n), st%phase(nd), &
                st%q(n), st%p(n), st%uc(n), st%b1(n), st%f0(max(nd, 1)), &
                st%qc(n, 0:kmax + 1), st%pc(n, 0:kmax + 1), st%cp(n, 0:kmax + 1), st%g(0:kmax), st%gn(0:kmax), &
                st%yc(0:kmax, nqt), st%yrem(nqt), st%ec(0:kmax, 2*nd), st%erem(2*nd), st%eta(2*nd), &
                st%offs(2*nd), st%eon(2*nd), st%pw(0:kmax, 0:max_depth), st%pw2(0:kmax), st%pc1(0:kmax), &
                st%roots(kmax), st%wm(nd, nd), st%lq(nd), st%lqa(nd), st%lo(nd), st%hi(nd), st%z(nd), st%w(nd), &
                st%zs(nd), st%cand(nd), st%sig(nd), st%newph(nd), st%oldph(nd), st%crossed(nd), st%near(nd), &
                st%fn(n), st%pe(n), st%pa(n), st%aab(n), st%qa(n, 0:kmax + 1), st%pq(n, 0:kmax + 1), stat=stat)
      call allocation_error(error, stat, "the exact technique's state of n_dof = "//trim(fmt_int(n))// &
                            " DOFs and n_devices = "//trim(fmt_int(nd))//" devices")
      if (allocated(error)) return
      st%mass = model%mass
      do d = 1, n
         st%rinf(d) = influence_of(model, d)
      end do
      do d = 1, nd
         st%slip(d) = model%dev(d)%p*model%dev(d)%mu
         st%active(d) = st%slip(d) > 0.0_dp
      end do
      st%phase = phase_stick
      st%offs = 0.0_dp
      st%eon = .false.
      st%crossed = .false.
      call cache_init(st%cache, n, nd, error)
      if (allocated(error)) return
      if (nd > 0) then
         call lcp_init(st%lcp, nd, nd, error)
         if (allocated(error)) return
      end if
   end subroutine ed_setup

   !> The polynomials of the current pattern on [0, span] from the current instant t:
   !> Taylor coefficients of the state, every output quantity and every event function,
   !> their remainder bounds and rounding levels.
   subroutine ed_polynomials(model, exc, t, span, st)
      type(model_type), intent(in) :: model         !! the model
      type(excitation_type), intent(in) :: exc      !! the table motion
      real(dp), intent(in) :: t                     !! the current instant [s]
      real(dp), intent(in) :: span                  !! sub-interval length S
      type(ed_state), intent(inout) :: st           !! the state
      integer :: i, d, kk, gi, gj, r, ni, nj, e, j
      real(dp) :: rg, sk, a0, x

      associate (pat => st%cache%slot(st%cur))
         st%span = span
         ! the degree the pattern needs at most (its a priori bound) and a margin
         kk = min(kmax, pat%order + 4)
         call table_taylor(exc, t, st%g(0:kk), st%gn(0:kk))
         call pattern_series(pat, st%q, st%p, st%b1, st%g(0:kk), st%gn(0:kk), span, st%qc, st%pc, st%cp, &
                             st%order, st%rem, st%size, st%grem, st%gsize)
         kk = st%order
         rg = st%grem                           ! remainder of ag: gn(K) S^(K+1)
         ! the magnitude of the terms that make up each group's acceleration: the rounding
         ! level of the velocities' and forces' variation over the sub-interval
         do i = 1, pat%nq
            a0 = abs(st%b1(i)) + abs(st%g(0))*abs(pat%lq(i))
            do j = 1, pat%nq
               a0 = a0 + abs(pat%kt(i, j)*st%q(j)) + abs(pat%ct(i, j)*st%p(j))
            end do
            st%aab(i) = a0
         end do
         ! per DOF: u, v, aabs
         do i = 1, st%n
            gi = pat%grp(i)
            if (pat%general) then
               call general_dof(st, i, kk, rg)
            else if (gi == 0) then
               st%yc(0:kk, iq_u(i)) = 0.0_dp
               st%yc(0, iq_u(i)) = st%uc(i)
               st%yc(0:kk, iq_v(i)) = 0.0_dp
               st%yc(0:kk, iq_a(i)) = st%g(0:kk)
               st%yrem(iq_u(i)) = 0.0_dp
               st%yrem(iq_v(i)) = 0.0_dp
               st%yrem(iq_a(i)) = rg
            else
               st%yc(0:kk, iq_u(i)) = st%qc(gi, 0:kk)
               st%yc(0, iq_u(i)) = st%yc(0, iq_u(i)) + st%uc(i)
               st%yc(0:kk, iq_v(i)) = st%pc(gi, 0:kk)
               do j = 0, kk
                  st%yc(j, iq_a(i)) = (j + 1)*st%pc(gi, j + 1) + st%g(j)
               end do
               st%yrem(iq_u(i)) = pat%wq(gi)*st%rem
               st%yrem(iq_v(i)) = pat%wp(gi)*st%rem
               st%yrem(iq_a(i)) = pat%wacc(gi)*st%rem
            end if
         end do
         ! per device: s, F, and the event functions
         do d = 1, st%nd
            if (pat%general) then
               call general_device(model, st, d, kk)
               gi = 0
               gj = 0
            else
               call pair_nodes(model, d, ni, nj)
               st%yc(0:kk, iq_s(st%n, d)) = st%yc(0:kk, iq_u(ni))
               gi = pat%grp(ni)
               gj = 0
               if (nj > 0) then
                  st%yc(0:kk, iq_s(st%n, d)) = st%yc(0:kk, iq_s(st%n, d)) - st%yc(0:kk, iq_u(nj))
                  gj = pat%grp(nj)
               end if
               st%yrem(iq_s(st%n, d)) = 0.0_dp
               if (gi /= gj) then
                  if (gi > 0) st%yrem(iq_s(st%n, d)) = pat%wq(gi)*st%rem
                  if (gj > 0) st%yrem(iq_s(st%n, d)) = st%yrem(iq_s(st%n, d)) + pat%wq(gj)*st%rem
               end if
            end if
            e = 2*d - 1
            r = pat%row(d)
            if (.not. st%active(d)) then
               st%yc(0:kk, iq_f(st%n, d)) = 0.0_dp
               st%yrem(iq_f(st%n, d)) = 0.0_dp
               st%eon(e:e + 1) = .false.
            else if (r == 0) then
               ! sliding: F = sgn P mu; event function sgn s'
               st%yc(0:kk, iq_f(st%n, d)) = 0.0_dp
               st%yc(0, iq_f(st%n, d)) = st%phase(d)*st%slip(d)
               st%yrem(iq_f(st%n, d)) = 0.0_dp
               st%eon(e) = .true.
               st%eon(e + 1) = .false.
               if (pat%general) then
                  call general_slide_event(st, d, e, kk, span)
                  cycle
               end if
               a0 = 0.0_dp
               st%erem(e) = 0.0_dp
               do j = 0, kk
                  x = 0.0_dp
                  if (gi > 0) x = st%pc(gi, j)
                  if (gj > 0) x = x - st%pc(gj, j)
                  st%ec(j, e) = st%phase(d)*x
               end do
               if (gi > 0) then
                  a0 = a0 + abs(st%pc(gi, 0)) + span*st%aab(gi)
                  st%erem(e) = st%erem(e) + pat%wp(gi)*st%rem
               end if
               if (gj > 0) then
                  a0 = a0 + abs(st%pc(gj, 0)) + span*st%aab(gj)
                  st%erem(e) = st%erem(e) + pat%wp(gj)*st%rem
               end if
               st%eta(e) = 256.0_dp*epsilon(1.0_dp)*(a0 + poly_abs_bound(st%ec(0:kk, e), span))
            else
               ! sticking: F from the force map; event functions P mu - F and P mu + F
               associate (f => st%yc(0:kk, iq_f(st%n, d)))
                  a0 = abs(st%f0(r)) + abs(pat%fag(r)*st%g(0)) + st%slip(d)
                  do j = 0, kk
                     sk = pat%fag(r)*st%g(j)
                     do i = 1, pat%nq
                        sk = sk + pat%fq(r, i)*st%qc(i, j) + pat%fp(r, i)*st%pc(i, j)
                     end do
                     f(j + 1) = sk
                  end do
                  f(1) = f(1) + st%f0(r)
                  a0 = a0 + span*abs(pat%fag(r)*st%g(1))
                  do i = 1, pat%nq
                     a0 = a0 + abs(pat%fq(r, i)*st%qc(i, 0)) + abs(pat%fp(r, i)*st%pc(i, 0)) + &
                          span*(abs(pat%fq(r, i)*st%pc(i, 0)) + abs(pat%fp(r, i))*st%aab(i))
                  end do
                  st%yrem(iq_f(st%n, d)) = pat%wf(r)*st%rem + abs(pat%fag(r))*rg
                  st%ec(0:kk, e) = -f
                  st%ec(0:kk, e + 1) = f
                  st%ec(0, e) = st%ec(0, e) + st%slip(d)
                  st%ec(0, e + 1) = st%ec(0, e + 1) + st%slip(d)
                  st%eta(e) = 256.0_dp*epsilon(1.0_dp)*(a0 + poly_abs_bound(f, span))
               end associate
               st%eon(e:e + 1) = .true.
               st%eta(e + 1) = st%eta(e)
               st%erem(e:e + 1) = st%yrem(iq_f(st%n, d))
            end if
         end do
         do e = 1, 2*st%nd
            st%eta(e) = max(st%eta(e), 4.0_dp*st%erem(e), tiny(1.0_dp))
         end do
      end associate
   end subroutine ed_polynomials

   !> u_i, v_i and aabs_i of a general pattern: u = T q + uc, aabs = u'' + r ag.
   pure subroutine general_dof(st, i, kk, rg)
      type(ed_state), intent(inout) :: st           !! the state
      integer, intent(in) :: i, kk                  !! the DOF, the degree
      real(dp), intent(in) :: rg                    !! the table acceleration's remainder
      integer :: g, j
      real(dp) :: wu, wv, wa

      associate (pat => st%cache%slot(st%cur))
         st%yc(0:kk, iq_u(i)) = 0.0_dp
         st%yc(0:kk, iq_v(i)) = 0.0_dp
         do j = 0, kk
            st%yc(j, iq_a(i)) = st%rinf(i)*st%g(j)
         end do
         wu = 0.0_dp
         wv = 0.0_dp
         wa = 0.0_dp
         do g = 1, pat%nq
            st%yc(0:kk, iq_u(i)) = st%yc(0:kk, iq_u(i)) + pat%tm(i, g)*st%qc(g, 0:kk)
            st%yc(0:kk, iq_v(i)) = st%yc(0:kk, iq_v(i)) + pat%tm(i, g)*st%pc(g, 0:kk)
            do j = 0, kk
               st%yc(j, iq_a(i)) = st%yc(j, iq_a(i)) + pat%tm(i, g)*((j + 1)*st%pc(g, j + 1))
            end do
            wu = wu + abs(pat%tm(i, g))*pat%wq(g)
            wv = wv + abs(pat%tm(i, g))*pat%wp(g)
            wa = wa + abs(pat%tm(i, g))*pat%wacc(g)
         end do
         st%yc(0, iq_u(i)) = st%yc(0, iq_u(i)) + st%uc(i)
         st%yrem(iq_u(i)) = wu*st%rem
         st%yrem(iq_v(i)) = wv*st%rem
         st%yrem(iq_a(i)) = wa*st%rem + abs(st%rinf(i))*rg
      end associate
   end subroutine general_dof

   !> s_d = b_d' u of a general pattern: (T'b_d)' q + b_d' uc, and its remainder.
   pure subroutine general_device(model, st, d, kk)
      type(model_type), intent(in) :: model         !! the model
      type(ed_state), intent(inout) :: st           !! the state
      integer, intent(in) :: d, kk                  !! the device, the degree
      integer :: g
      real(dp) :: wu

      associate (pat => st%cache%slot(st%cur))
         st%yc(0:kk, iq_s(st%n, d)) = 0.0_dp
         wu = 0.0_dp
         do g = 1, pat%nq
            st%yc(0:kk, iq_s(st%n, d)) = st%yc(0:kk, iq_s(st%n, d)) + pat%tb(g, d)*st%qc(g, 0:kk)
            wu = wu + abs(pat%tb(g, d))*pat%wq(g)
         end do
         st%yc(0, iq_s(st%n, d)) = st%yc(0, iq_s(st%n, d)) + device_relative(model, d, st%uc)
         st%yrem(iq_s(st%n, d)) = wu*st%rem
      end associate
   end subroutine general_device

   !> A sliding device's event function sgn s' in a general pattern, its remainder and its
   !> rounding level.
   pure subroutine general_slide_event(st, d, e, kk, span)
      type(ed_state), intent(inout) :: st           !! the state
      integer, intent(in) :: d, e, kk               !! the device, its event function, the degree
      real(dp), intent(in) :: span                  !! sub-interval length
      integer :: g, j
      real(dp) :: a0

      associate (pat => st%cache%slot(st%cur))
         st%ec(0:kk, e) = 0.0_dp
         st%erem(e) = 0.0_dp
         a0 = 0.0_dp
         do g = 1, pat%nq
            do j = 0, kk
               st%ec(j, e) = st%ec(j, e) + st%phase(d)*pat%tb(g, d)*st%pc(g, j)
            end do
            st%erem(e) = st%erem(e) + abs(pat%tb(g, d))*pat%wp(g)*st%rem
            a0 = a0 + abs(pat%tb(g, d))*(abs(st%pc(g, 0)) + span*st%aab(g))
         end do
         st%eta(e) = 256.0_dp*epsilon(1.0_dp)*(a0 + poly_abs_bound(st%ec(0:kk, e), span))
      end associate
   end subroutine general_slide_event

end module fd_ed_state
