!> The reduced linear system of one phase pattern of the exact technique, its closed form
!> between events, and the cache of the patterns met.
!>
!> With the sticking devices rigid links, the nodes they join form groups (none for a
!> group holding the table); one reduced coordinate q per group, u = T q + uc (uc: the
!> constant offsets inside each group), p = q':
!>   Mq p' = -Kq q - Cq p + T'(-K uc - sum_slide b_d sgn_d P mu_d) - Mq 1 ag(t)
!> (Mq = T'MT diagonal, Kq = T'KT, Cq = T'CT). The sticking devices carry the forces
!> B_S F = r(q, p, ag) that keep them stuck, r = -M (1 ag + u'') - C u' - K u - B_sl F_sl;
!> F is the solution that minimizes sum F_d^2 / (P mu_d) (unique for a statically
!> determinate set; for redundant devices, e.g. in parallel, it shares the force in
!> proportion to the limits, so that they reach them together): F = D (B_S D)^+ r,
!> D = diag(sqrt(P mu)), a linear map of (q, p, ag) plus a constant set at each entry.
!>
!> **Closed form.** On a sub-interval [0, S] from an instant a, x = (q, p) is its Taylor
!> polynomial of degree K, x_0 = x(a), x_{k+1} = (A x_k + [k = 0] b1 + bag g_k)/(k + 1)
!> (g_k: the table acceleration's Taylor coefficients, exact for sines and linear
!> pieces), plus a remainder R. In the norm ||x||^2 = p'Mq p + q'(Kq + alpha^2 Mq) q the
!> free motion grows at most like exp(alpha s / 2) (d/ds of the norm's square is
!> -2 p'Cq p + 2 alpha^2 q'Mq p <= alpha ||x||^2), and x^(K+1) is a free motion driven by
!> ag^(K+1), so that
!>   ||R(s)|| <= exp(alpha s/2) (||x_{K+1}|| s^(K+1) + s^(K+2) sqrt(1'Mq 1) gnext),
!> gnext >= sup |ag^(K+1)| / (K+1)!: a bound computed on every sub-interval, whatever
!> the pattern (rigid-body modes, a sliding mass without spring, critical damping: no
!> eigen-decomposition, nothing defective). S and K are chosen per pattern so that the
!> bound, and the table acceleration's own remainder gn(K) S^(K+1) (it enters the sticking
!> forces and the absolute accelerations directly: with nq = 0 it is the whole solution),
!> are below the rounding level: S = 1 / (2 w + c + w_f) (w^2, c: bounds of the
!> spectra of Mq^-1 Kq and Mq^-1 Cq; w_f: the table's highest frequency), alpha = 1/S.
!> A component is bounded by the norm: |q_g| <= ||x|| / (alpha sqrt(mq_g)),
!> |p_g| <= ||x|| / sqrt(mq_g), which gives the remainder of every output quantity.
!>
!> **Devices of any direction, stiffness beyond springs.** When a device is not between two
!> nodes, K has entries beyond springs (K_x) or the table motion has a direction r over the
!> DOFs (general_pattern), the sticking devices' constraints B_S' u = const are no groups of
!> nodes: T is then an M-orthonormal basis of the null space of B_S' (an orthonormal basis
!> Z from the eigenvectors of B_S B_S', then the modes of (Z'KZ, Z'MZ), so that T'MT = I and
!> Mq = I), u = T q + uc with q = T'M u, and the table's load on each coordinate is
!> -lq ag, lq = T'M r (1 for a group). The closed form, its bounds and the force map are
!> the same with these T, Mq and lq; T and T'B are kept with the pattern.
!>
!> **Cache.** A pattern is built once (its groups, reduced matrices and force map: one
!> SVD) and kept in a cache keyed by the phases, so that an event costs a lookup; the
!> cache holds at most `nslots` patterns (least recently used replaced).
module fd_phase_pattern
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, allocation_error
   use fd_model, only: model_type
   use fd_excitation, only: excitation_type, forcing_frequency
   use fd_matrices, only: link_groups, device_null_space
   use fd_kinematics, only: add_device, devices_are_pairs
   use fd_stiffness, only: influence_of
   use fd_linalg, only: least_squares, least_squares_work, generalized_eigen
   use fd_device_state, only: phase_stick
   implicit none
   private

   public :: pattern_type, pattern_cache, cache_init, cache_find, build_pattern, pattern_entry
   public :: pattern_taylor, pattern_series, remainder_bound, kmax, general_pattern, null_space_basis

   integer, parameter :: kmax = 40                !! largest Taylor degree
   real(dp), parameter :: theta = 1.0_dp          !! (2 w + c + w_f) S: sub-interval length
   real(dp), parameter :: max_sub = 1.0_dp        !! longest sub-interval [s]

   !> One phase pattern: groups, reduced matrices, force map, sub-interval and degree.
   type :: pattern_type
      integer, allocatable :: key(:)                 !! phases (nd): the cache key
      integer :: nq = 0                              !! reduced coordinates
      integer :: ns = 0                              !! sticking active devices
      integer, allocatable :: grp(:)                 !! group of each DOF (0 = with the table)
      integer, allocatable :: ids(:)                 !! the sticking devices (ns)
      integer, allocatable :: row(:)                 !! row of device d in the force map (0: none)
      real(dp), allocatable :: mq(:)                 !! group masses (nq); 1 in a general pattern
      real(dp), allocatable :: lq(:)                 !! table load per unit mass of each coordinate (nq)
      logical :: general = .false.                   !! coordinates T q over a null space, not groups
      real(dp), allocatable :: tm(:, :)              !! general: T (n, nq), T'MT = I
      real(dp), allocatable :: tb(:, :)              !! general: T'b_d (nq, nd)
      real(dp), allocatable :: kt(:, :), ct(:, :)    !! Mq^-1 Kq, Mq^-1 Cq (nq, nq)
      real(dp), allocatable :: pinv(:, :)            !! D (B_S D)^+ (ns, n), D = diag(sqrt(P mu))
      real(dp), allocatable :: fq(:, :), fp(:, :)    !! force map: F = fq q + fp p + fag ag + f0
      real(dp), allocatable :: fag(:)                !! (ns)
      real(dp) :: delta = 0.0_dp                     !! sub-interval length S [s]
      real(dp) :: alpha = 0.0_dp                     !! norm weight 1/S [1/s]
      integer :: order = 2                           !! Taylor degree K
      real(dp), allocatable :: wq(:), wp(:)          !! |q_g| <= wq ||x||, |p_g| <= wp ||x||
      real(dp), allocatable :: wacc(:), wf(:)        !! same for accelerations (nq), forces (ns)
      real(dp) :: msum = 0.0_dp                      !! sqrt(sum mq): the norm of the table's load
      real(dp) :: w2 = 0.0_dp                        !! bound of the spectrum of Mq^-1 Kq
      integer :: last_use = 0                        !! clock of the last use
   end type pattern_type

   !> The patterns met, keyed by their phases.
   type :: pattern_cache
      integer :: nslots = 0                          !! capacity
      integer :: nused = 0                           !! slots holding a pattern
      integer :: clock = 0                           !! use counter
      integer :: builds = 0                          !! patterns built
      integer :: tsize = 0                           !! hash table size (power of 2)
      type(pattern_type), allocatable :: slot(:)     !! the patterns
      integer, allocatable :: table(:)               !! hash -> slot (0: empty)
   end type pattern_cache

contains

   !> Size the cache of a model with n DOFs and nd devices: as many patterns as 3^nd, at
   !> most 4096, and at most what 256 MB hold.
   subroutine cache_init(cache, n, nd, error)
      type(pattern_cache), intent(out) :: cache           !! the cache
      integer, intent(in) :: n                            !! DOFs
      integer, intent(in) :: nd                           !! devices
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      real(dp) :: bytes
      integer :: stat

      bytes = 8.0_dp*(2.0_dp*n*n + 4.0_dp*nd*n + 10.0_dp*n + 4.0_dp*nd) + 2000.0_dp
      cache%nslots = int(min(4096.0_dp, 3.0_dp**min(nd, 12), max(8.0_dp, 2.56e8_dp/bytes)))
      cache%tsize = 16
      do while (cache%tsize < 2*cache%nslots)
         cache%tsize = 2*cache%tsize
      end do
      allocate (cache%slot(cache%nslots), cache%table(0:cache%tsize - 1), stat=stat)
      call allocation_error(error, stat, "the cache of "//trim(fmt_int(cache%nslots))//" phase patterns")
      if (allocated(error)) return
      cache%table = 0
   end subroutine cache_init

   pure integer function hash_of(phase, tsize) result(h)
      integer, intent(in) :: phase(:)
      integer, intent(in) :: tsize
      integer :: d
      integer, parameter :: i8 = selected_int_kind(18)
      integer(i8) :: x

      x = 1469598103_i8
      do d = 1, size(phase)
         x = mod(x*31_i8 + int(phase(d) + 2, i8), 2147483647_i8)
      end do
      h = int(iand(x, int(tsize - 1, i8)))
   end function hash_of

   !> The slot of the pattern with these phases, building it when new (or replacing the
   !> least recently used one in a full cache; `pinned` slots are not replaced).
   subroutine cache_find(cache, model, mass, k, c, active, phase, slip, exc, pinned, islot, error)
      type(pattern_cache), intent(inout) :: cache   !! the cache
      type(model_type), intent(in) :: model         !! the model
      real(dp), intent(in) :: mass(:)               !! lumped masses
      real(dp), intent(in) :: k(:, :), c(:, :)      !! stiffness, damping
      logical, intent(in) :: active(:)              !! devices with P mu > 0
      integer, intent(in) :: phase(:)               !! phases (0 stick, +-1 slide)
      real(dp), intent(in) :: slip(:)               !! P mu
      type(excitation_type), intent(in) :: exc      !! the table motion
      integer, intent(in) :: pinned(:)              !! slots not to replace
      integer, intent(out) :: islot                 !! the pattern's slot
      type(error_type), allocatable, intent(out) :: error !! failed build
      integer :: h, j, oldest

      cache%clock = cache%clock + 1
      h = hash_of(phase, cache%tsize)
      do
         islot = cache%table(h)
         if (islot == 0) exit
         if (all(cache%slot(islot)%key == phase)) then
            cache%slot(islot)%last_use = cache%clock
            return
         end if
         h = iand(h + 1, cache%tsize - 1)
      end do
      ! new pattern: a free slot, or the least recently used one
      if (cache%nused < cache%nslots) then
         cache%nused = cache%nused + 1
         islot = cache%nused
         cache%table(h) = islot
      else
         oldest = huge(1)
         islot = 1
         do j = 1, cache%nslots
            if (any(pinned == j)) cycle
            if (cache%slot(j)%last_use < oldest) then
               oldest = cache%slot(j)%last_use
               islot = j
            end if
         end do
         call free_pattern(cache%slot(islot))
         cache%slot(islot)%key = phase    ! (re)allocated: the new pattern's key
         call rehash(cache)
      end if
      call build_pattern(model, mass, k, c, active, phase, slip, exc, cache%slot(islot), error)
      if (allocated(error)) return
      cache%slot(islot)%last_use = cache%clock
      cache%builds = cache%builds + 1
   end subroutine cache_find

   subroutine rehash(cache)
      type(pattern_cache), intent(inout) :: cache
      integer :: j, h

      cache%table = 0
      do j = 1, cache%nused
         if (.not. allocated(cache%slot(j)%key)) cycle
         h = hash_of(cache%slot(j)%key, cache%tsize)
         do while (cache%table(h) /= 0)
            h = iand(h + 1, cache%tsize - 1)
         end do
         cache%table(h) = j
      end do
   end subroutine rehash

   subroutine free_pattern(pat)
      type(pattern_type), intent(inout) :: pat
      if (allocated(pat%key)) deallocate (pat%key)
      if (allocated(pat%grp)) deallocate (pat%grp, pat%ids, pat%row, pat%mq, pat%kt, pat%ct, pat%pinv, &
                                           pat%fq, pat%fp, pat%fag, pat%wq, pat%wp, pat%wacc, pat%wf, pat%lq)
      if (allocated(pat%tm)) deallocate (pat%tm)
      if (allocated(pat%tb)) deallocate (pat%tb)
   end subroutine free_pattern

   !> Build the pattern of these phases: groups, reduced matrices, force map, sub-interval
   !> length and Taylor degree.
   subroutine build_pattern(model, mass, k, c, active, phase, slip, exc, pat, error)
      type(model_type), intent(in) :: model         !! the model (device nodes)
      real(dp), intent(in) :: mass(:)               !! lumped masses
      real(dp), intent(in) :: k(:, :)               !! springs' stiffness
      real(dp), intent(in) :: c(:, :)               !! viscous damping
      logical, intent(in) :: active(:)              !! devices with P mu > 0
      integer, intent(in) :: phase(:)               !! device phases (0 stick, +-1 slip)
      real(dp), intent(in) :: slip(:)               !! P mu of each device
      type(excitation_type), intent(in) :: exc      !! the table motion (its frequencies)
      type(pattern_type), intent(inout) :: pat      !! the pattern
      type(error_type), allocatable, intent(out) :: error !! no memory, failed SVD
      real(dp), allocatable :: kq(:, :), cq(:, :), a(:, :), b(:, :), sv(:), lwk(:), mk(:, :), mc(:, :)
      integer :: n, nd, nq, ns, i, j, g, d, r, info, stat
      real(dp) :: w2, cb, wf, lam, mu, term, sd
      integer :: kk

      n = size(mass)
      nd = size(phase)
      call free_pattern(pat)
      allocate (pat%key(nd), pat%grp(n), pat%row(nd), stat=stat)
      call allocation_error(error, stat, trim(pattern_text(n, nd)))
      if (allocated(error)) return
      pat%key = phase
      pat%general = general_pattern(model)
      if (pat%general) then
         pat%grp = -1
         call null_space_basis(model, mass, active .and. phase == phase_stick, pat%tm, nq, error)
         if (allocated(error)) return
      else
         call link_groups(model, active .and. phase == phase_stick, pat%grp, nq)
      end if
      ns = count(active .and. phase == phase_stick)
      pat%nq = nq
      pat%ns = ns
      allocate (pat%ids(ns), pat%mq(nq), pat%kt(nq, nq), pat%ct(nq, nq), pat%pinv(ns, n), pat%fq(ns, nq), &
                pat%fp(ns, nq), pat%fag(ns), pat%wq(nq), pat%wp(nq), pat%wacc(nq), pat%wf(ns), pat%lq(nq), &
                kq(nq, nq), cq(nq, nq), stat=stat)
      call allocation_error(error, stat, trim(pattern_text(n, nd)))
      if (allocated(error)) return
      pat%lq = 1.0_dp
      pat%row = 0
      r = 0
      do d = 1, nd
         if (.not. active(d) .or. phase(d) /= phase_stick) cycle
         r = r + 1
         pat%ids(r) = d
         pat%row(d) = r
      end do
      if (pat%general) then
         call general_reduced(model, mass, k, c, pat, kq, cq, error)
         if (allocated(error)) return
      else
         call group_reduced(mass, k, c, pat, kq, cq)
      end if
      do g = 1, nq
         pat%kt(g, :) = kq(g, :)/pat%mq(g)
         pat%ct(g, :) = cq(g, :)/pat%mq(g)
      end do
      ! sub-interval and degree (module header)
      w2 = 0.0_dp
      cb = 0.0_dp
      do g = 1, nq
         w2 = max(w2, sum(abs(pat%kt(g, :))))
         cb = max(cb, sum(abs(pat%ct(g, :))))
      end do
      wf = forcing_frequency(exc)
      pat%delta = min(max_sub, theta/max(2.0_dp*sqrt(w2) + cb + wf, theta/max_sub))
      pat%alpha = 1.0_dp/pat%delta
      lam = sqrt(w2 + pat%alpha**2) + sqrt(w2) + cb
      mu = max(lam, wf)*pat%delta
      term = exp(0.5_dp)
      kk = 0
      do
         kk = kk + 1
         term = term*mu/kk
         if ((term <= 2.0_dp**(-54) .and. kk >= 3) .or. kk == kmax + 1) exit
      end do
      pat%order = max(5, kk - 1)
      pat%w2 = w2
      pat%msum = sqrt(sum(pat%mq*pat%lq**2))
      do g = 1, nq
         pat%wp(g) = 1.0_dp/sqrt(pat%mq(g))
         pat%wq(g) = pat%wp(g)/pat%alpha
      end do
      do g = 1, nq
         pat%wacc(g) = sum(abs(pat%kt(g, :))*pat%wq) + sum(abs(pat%ct(g, :))*pat%wp)
      end do
      if (ns == 0) return
      ! force map F = D (B_S D)^+ r, r = (M T Kt - K T) q + (M T Ct - C T) p - m[grp = 0] ag + ...
      allocate (a(n, ns), b(max(n, ns), n), sv(min(n, ns)), lwk(least_squares_work(n, ns)), mk(n, nq), &
                mc(n, nq), stat=stat)
      call allocation_error(error, stat, trim(pattern_text(n, nd)))
      if (allocated(error)) return
      a = 0.0_dp
      do r = 1, ns
         call add_device(model, pat%ids(r), sqrt(slip(pat%ids(r))), a(:, r))
      end do
      b = 0.0_dp
      do i = 1, n
         b(i, i) = 1.0_dp
      end do
      call least_squares(a, b, sv, lwk, info)
      if (info /= 0) then
         call fatal_error(error, "the SVD of the "//trim(fmt_int(ns))//" sticking devices' incidence failed "// &
                          "(LAPACK dgelss info = "//trim(fmt_int(info))//")")
         return
      end if
      ! (singular values below the rounding level count as zero: dgelss with rcond = eps)
      do r = 1, ns
         pat%pinv(r, :) = sqrt(slip(pat%ids(r)))*b(r, 1:n)
      end do
      if (pat%general) then
         call general_force_map(model, mass, k, c, pat, error)
         return
      end if
      do i = 1, n
         g = pat%grp(i)
         do j = 1, nq
            sd = 0.0_dp
            term = 0.0_dp
            if (g > 0) then
               sd = mass(i)*pat%kt(g, j)
               term = mass(i)*pat%ct(g, j)
            end if
            mk(i, j) = sd
            mc(i, j) = term
         end do
         do j = 1, n
            g = pat%grp(j)
            if (g == 0) cycle
            mk(i, g) = mk(i, g) - k(i, j)
            mc(i, g) = mc(i, g) - c(i, j)
         end do
      end do
      pat%fq = matmul(pat%pinv, mk)
      pat%fp = matmul(pat%pinv, mc)
      pat%fag = 0.0_dp
      do i = 1, n
         if (pat%grp(i) == 0) pat%fag = pat%fag - pat%pinv(:, i)*mass(i)
      end do
      do r = 1, ns
         pat%wf(r) = sum(abs(pat%fq(r, :))*pat%wq) + sum(abs(pat%fp(r, :))*pat%wp)
      end do
   end subroutine build_pattern

   !> A pattern of groups' reduced matrices: the group masses Mq, Kq = T'KT, Cq = T'CT (T the
   !> 0/1 matrix of the groups).
   pure subroutine group_reduced(mass, k, c, pat, kq, cq)
      real(dp), intent(in) :: mass(:), k(:, :), c(:, :) !! structure
      type(pattern_type), intent(inout) :: pat      !! the pattern, grp set
      real(dp), intent(out) :: kq(:, :), cq(:, :)   !! (nq, nq)
      integer :: i, j, n

      n = size(mass)
      pat%mq = 0.0_dp
      kq = 0.0_dp
      cq = 0.0_dp
      do i = 1, n
         if (pat%grp(i) == 0) cycle
         pat%mq(pat%grp(i)) = pat%mq(pat%grp(i)) + mass(i)
         do j = 1, n
            if (pat%grp(j) == 0) cycle
            kq(pat%grp(i), pat%grp(j)) = kq(pat%grp(i), pat%grp(j)) + k(i, j)
            cq(pat%grp(i), pat%grp(j)) = cq(pat%grp(i), pat%grp(j)) + c(i, j)
         end do
      end do
   end subroutine group_reduced

   !> What a phase pattern's memory is for, in a message: "a phase pattern of n DOFs and nd
   !> devices".
   pure function pattern_text(n, nd) result(text)
      integer, intent(in) :: n                      !! DOFs
      integer, intent(in) :: nd                     !! devices
      character(len=80) :: text
      text = "a phase pattern of "//trim(fmt_int(n))//" DOFs and "//trim(fmt_int(nd))//" devices"
   end function pattern_text

   !> Enter a pattern at a state (u, v): the reduced state (q: the mass-weighted mean of
   !> each group; a general pattern's q = T'M u, p = T'M v), the offsets uc = u - T q, v
   !> projected on the constraints (v = T p), the constant load b1 of the reduced system
   !> (T' fn, over each group's mass for groups) and the constant term f0 = pinv (fn - M T b1)
   !> of the force map, fn = -K uc - sum_slide b sgn P mu. Work fn (n) is overwritten.
   pure subroutine pattern_entry(pat, model, mass, k, phase, slip, u, v, q, p, uc, b1, f0, fn)
      type(pattern_type), intent(in) :: pat         !! the pattern
      type(model_type), intent(in) :: model         !! the model (device nodes)
      real(dp), intent(in) :: mass(:)               !! lumped masses
      real(dp), intent(in) :: k(:, :)               !! springs' stiffness
      integer, intent(in) :: phase(:)               !! the pattern's phases
      real(dp), intent(in) :: slip(:)               !! P mu
      real(dp), intent(in) :: u(:)                  !! displacements
      real(dp), intent(inout) :: v(:)               !! velocities, projected on return
      real(dp), intent(out) :: q(:), p(:)           !! reduced state (nq used)
      real(dp), intent(out) :: uc(:)                !! offsets (n)
      real(dp), intent(out) :: b1(:)                !! constant load of the reduced system (nq used)
      real(dp), intent(out) :: f0(:)                !! constant term of the force map (ns used)
      real(dp), intent(inout) :: fn(:)              !! work (n)
      integer :: i, j, g, n, d, nq

      n = size(mass)
      nq = pat%nq
      q(1:nq) = 0.0_dp
      p(1:nq) = 0.0_dp
      if (pat%general) then
         do g = 1, nq
            q(g) = sum(pat%tm(:, g)*mass*u)
            p(g) = sum(pat%tm(:, g)*mass*v)
         end do
         uc = u
         v = 0.0_dp
         do g = 1, nq
            uc = uc - pat%tm(:, g)*q(g)
            v = v + pat%tm(:, g)*p(g)
         end do
         fn = -matmul(k, uc)
      else
         do i = 1, n
            g = pat%grp(i)
            if (g == 0) cycle
            q(g) = q(g) + mass(i)*u(i)
            p(g) = p(g) + mass(i)*v(i)
         end do
         do g = 1, nq
            q(g) = q(g)/pat%mq(g)
            p(g) = p(g)/pat%mq(g)
         end do
         do i = 1, n
            g = pat%grp(i)
            if (g == 0) then
               uc(i) = u(i)
               v(i) = 0.0_dp
            else
               uc(i) = u(i) - q(g)
               v(i) = p(g)
            end if
         end do
         ! fn = -K uc
         fn = 0.0_dp
         do j = 1, n
            if (uc(j) == 0.0_dp) cycle
            do i = 1, n
               fn(i) = fn(i) - k(i, j)*uc(j)
            end do
         end do
      end if
      ! the sliding devices' loads
      do d = 1, size(phase)
         if (phase(d) == phase_stick .or. slip(d) <= 0.0_dp) cycle
         call add_device(model, d, -phase(d)*slip(d), fn)
      end do
      if (pat%general) then
         do g = 1, nq
            b1(g) = sum(pat%tm(:, g)*fn)
         end do
         do g = 1, nq
            fn = fn - mass*pat%tm(:, g)*b1(g)
         end do
      else
         b1(1:nq) = 0.0_dp
         do i = 1, n
            g = pat%grp(i)
            if (g > 0) b1(g) = b1(g) + fn(i)
         end do
         do g = 1, nq
            b1(g) = b1(g)/pat%mq(g)
         end do
         do i = 1, n
            g = pat%grp(i)
            if (g > 0) fn(i) = fn(i) - mass(i)*b1(g)
         end do
      end if
      call pinv_times(pat, fn, f0)
   end subroutine pattern_entry

   !> Taylor coefficients of the reduced state about an instant to degree K + 1, K =
   !> ubound(g): qc(:, k), pc(:, k) for k = 0..K+1 from q, p and the table acceleration's
   !> coefficients g(0:K), and cp(:, k) = Cq pc(:, k) (k = 0..K).
   pure subroutine pattern_taylor(pat, q, p, b1, g, qc, pc, cp)
      type(pattern_type), intent(in) :: pat         !! the pattern
      real(dp), intent(in) :: q(:), p(:)            !! reduced state (nq)
      real(dp), intent(in) :: b1(:)                 !! constant load (nq)
      real(dp), intent(in) :: g(0:)                 !! table acceleration's coefficients (0:K)
      real(dp), intent(out) :: qc(:, 0:), pc(:, 0:) !! coefficients (n, 0:K+1), rows 1..nq used
      real(dp), intent(out) :: cp(:, 0:)            !! Cq pc (n, 0:K)
      integer :: kk, nq

      nq = pat%nq
      if (nq == 0) return
      qc(1:nq, 0) = q(1:nq)
      pc(1:nq, 0) = p(1:nq)
      do kk = 0, ubound(g, 1)
         call taylor_step(pat, kk, g(kk), b1, qc, pc, cp)
      end do
   end subroutine pattern_taylor

   !> Taylor coefficients of the reduced state about an instant over [0, span], to the
   !> lowest degree K (at least 5) at which both remainders are below 2^-52 of their
   !> polynomials' sizes: the state's (the bound of its norm, module header; q'Kq q bounded
   !> by w2 q'Mq q) below 2^-52 sum_k ||x_k|| S^k, and the table acceleration's own,
   !> gn(K) S^(K+1), below 2^-52 sum_k |g_k| S^k (the table acceleration enters the output
   !> quantities and the sticking forces directly, not only through the state: for a pattern
   !> with no free coordinate, nq = 0, it is all there is); or to ubound(g). g, gn: the table
   !> acceleration's coefficients and remainder factors (0:kcap). Returns K and the bounds.
   pure subroutine pattern_series(pat, q, p, b1, g, gn, span, qc, pc, cp, order, rem, size, grem, gsize)
      type(pattern_type), intent(in) :: pat         !! the pattern
      real(dp), intent(in) :: q(:), p(:)            !! reduced state (nq)
      real(dp), intent(in) :: b1(:)                 !! constant load (nq)
      real(dp), intent(in) :: g(0:), gn(0:)         !! table acceleration (0:kmax)
      real(dp), intent(in) :: span                  !! sub-interval length S
      real(dp), intent(out) :: qc(:, 0:), pc(:, 0:) !! coefficients (n, 0:kmax+1), rows 1..nq used
      real(dp), intent(out) :: cp(:, 0:)            !! Cq pc (n, 0:kmax)
      integer, intent(out) :: order                 !! the degree K
      real(dp), intent(out) :: rem                  !! bound of the remainder's norm over [0, S]
      real(dp), intent(out) :: size                 !! sum_k ||x_k|| S^k
      real(dp), intent(out) :: grem                 !! bound of the table acceleration's remainder
      real(dp), intent(out) :: gsize                !! sum_k |g_k| S^k
      integer :: kk, nq, i
      real(dp) :: e, sk, grow, nrm

      nq = pat%nq
      order = 5
      rem = 0.0_dp
      size = 0.0_dp
      grem = 0.0_dp
      gsize = 0.0_dp
      grow = 1.0_dp
      if (nq > 0) then
         qc(1:nq, 0) = q(1:nq)
         pc(1:nq, 0) = p(1:nq)
         grow = exp(0.5_dp*pat%alpha*span)
      end if
      sk = 1.0_dp
      do kk = 0, ubound(g, 1)
         gsize = gsize + abs(g(kk))*sk
         if (nq > 0) then
            call taylor_step(pat, kk, g(kk), b1, qc, pc, cp)
            e = 0.0_dp
            nrm = 0.0_dp
            do i = 1, nq
               nrm = nrm + pat%mq(i)*(pc(i, kk)**2 + (pat%w2 + pat%alpha**2)*qc(i, kk)**2)
               e = e + pat%mq(i)*(pc(i, kk + 1)**2 + (pat%w2 + pat%alpha**2)*qc(i, kk + 1)**2)
            end do
            size = size + sqrt(nrm)*sk
         end if
         sk = sk*span
         grem = gn(kk)*sk
         if (nq > 0) rem = grow*(sqrt(e)*sk + sk*span*pat%msum*gn(kk))
         order = kk
         if (kk >= 5 .and. rem <= 2.0_dp**(-52)*size .and. grem <= 2.0_dp**(-52)*gsize) exit
      end do
   end subroutine pattern_series

   !> One step of the Taylor recursion: the coefficients of degree kk + 1 of q and p, and
   !> cp(:, kk) = Cq pc(:, kk), from those of degree kk (gk: the table acceleration's
   !> coefficient of degree kk; b1 enters at kk = 0).
   pure subroutine taylor_step(pat, kk, gk, b1, qc, pc, cp)
      type(pattern_type), intent(in) :: pat             !! the pattern
      integer, intent(in) :: kk                         !! degree done
      real(dp), intent(in) :: gk                        !! table acceleration, degree kk
      real(dp), intent(in) :: b1(:)                     !! constant load (nq)
      real(dp), intent(inout) :: qc(:, 0:), pc(:, 0:)   !! coefficients
      real(dp), intent(inout) :: cp(:, 0:)              !! Cq pc
      integer :: i, j, nq
      real(dp) :: f

      nq = pat%nq
      f = 1.0_dp/(kk + 1)
      do i = 1, nq
         qc(i, kk + 1) = pc(i, kk)*f
         pc(i, kk + 1) = -gk*pat%lq(i)
         cp(i, kk) = 0.0_dp
      end do
      if (kk == 0) pc(1:nq, 1) = pc(1:nq, 1) + b1(1:nq)
      do j = 1, nq
         do i = 1, nq
            pc(i, kk + 1) = pc(i, kk + 1) - pat%kt(i, j)*qc(j, kk)
            cp(i, kk) = cp(i, kk) + pat%ct(i, j)*pc(j, kk)
         end do
      end do
      do i = 1, nq
         pc(i, kk + 1) = (pc(i, kk + 1) - cp(i, kk))*f
         cp(i, kk) = cp(i, kk)*pat%mq(i)
      end do
   end subroutine taylor_step

   !> The bound on the norm of the remainder of the degree-K Taylor polynomial of the state
   !> over [0, s] (module header), from x_{K+1} = (qc(:, K+1), pc(:, K+1)).
   pure real(dp) function remainder_bound(pat, qc, pc, gnext, s) result(r)
      type(pattern_type), intent(in) :: pat         !! the pattern
      real(dp), intent(in) :: qc(:, 0:), pc(:, 0:)  !! coefficients (to K+1)
      real(dp), intent(in) :: gnext                 !! bound of |ag^(K+1)| / (K+1)!
      real(dp), intent(in) :: s                     !! sub-interval length
      integer :: i, j, kk
      real(dp) :: e, kqq

      r = 0.0_dp
      if (pat%nq == 0) return
      kk = pat%order + 1
      e = 0.0_dp
      do i = 1, pat%nq
         kqq = 0.0_dp
         do j = 1, pat%nq
            kqq = kqq + pat%kt(i, j)*qc(j, kk)
         end do
         e = e + pat%mq(i)*(pc(i, kk)**2 + qc(i, kk)*kqq + (pat%alpha*qc(i, kk))**2)
      end do
      r = exp(0.5_dp*pat%alpha*s)*(sqrt(max(e, 0.0_dp))*s**kk + s**(kk + 1)*pat%msum*gnext)
   end function remainder_bound

   !> Whether the model's patterns take general coordinates T q (module header): a device
   !> not between two nodes, stiffness beyond springs, or a table motion's direction r.
   pure logical function general_pattern(model) result(general)
      type(model_type), intent(in) :: model         !! the model

      general = .not. devices_are_pairs(model) .or. model%n_kx > 0 .or. allocated(model%influence)
   end function general_pattern

   !> T, an M-orthonormal basis of the null space of the linked devices' directions
   !> (b_d' T = 0, T'MT = I): Z, orthonormal, from fd_matrices' device_null_space (the
   !> null space the constrained modes use); Z'MZ = Y diag(lam) Y' and
   !> T = Z Y diag(lam)^-1/2. nq its columns.
   subroutine null_space_basis(model, mass, linked, tm, nq, error)
      type(model_type), intent(in) :: model         !! the model (directions)
      real(dp), intent(in) :: mass(:)               !! lumped masses
      logical, intent(in) :: linked(:)              !! the devices that constrain
      real(dp), allocatable, intent(out) :: tm(:, :) !! (n, nq)
      integer, intent(out) :: nq                    !! dimension of the null space
      type(error_type), allocatable, intent(out) :: error !! LAPACK failure, no memory
      real(dp), allocatable :: z(:, :), mz(:, :), eye(:, :), y(:, :), lam(:)
      integer :: n, i, j, stat

      n = size(mass)
      call device_null_space(model, linked, z, nq, error)
      if (allocated(error)) return
      allocate (tm(n, nq), mz(nq, nq), eye(nq, nq), y(nq, nq), lam(nq), stat=stat)
      call allocation_error(error, stat, trim(pattern_text(n, size(linked))))
      if (allocated(error)) return
      if (nq == 0) return
      ! Z'MZ = Y diag(lam) Y': T = Z Y diag(lam)^-1/2
      eye = 0.0_dp
      do j = 1, nq
         eye(j, j) = 1.0_dp
         do i = 1, nq
            mz(i, j) = sum(z(:, i)*mass*z(:, j))
         end do
      end do
      mz = 0.5_dp*(mz + transpose(mz))
      call generalized_eigen(mz, eye, lam, y, error)
      if (allocated(error)) return
      tm = matmul(z, y)
      do j = 1, nq
         tm(:, j) = tm(:, j)/sqrt(lam(j))
      end do
   end subroutine null_space_basis

   !> A general pattern's reduced matrices: Mq = I, Kq = T'KT, Cq = T'CT, lq = T'M r and
   !> T'b_d of every device.
   subroutine general_reduced(model, mass, k, c, pat, kq, cq, error)
      type(model_type), intent(in) :: model         !! the model
      real(dp), intent(in) :: mass(:), k(:, :), c(:, :) !! structure
      type(pattern_type), intent(inout) :: pat      !! the pattern, tm set
      real(dp), intent(out) :: kq(:, :), cq(:, :)   !! (nq, nq)
      type(error_type), allocatable, intent(out) :: error !! no memory
      real(dp), allocatable :: mr(:), col(:)
      integer :: n, nq, nd, i, d, stat

      n = size(mass)
      nq = pat%nq
      nd = model%n_devices
      allocate (pat%tb(nq, nd), mr(n), col(n), stat=stat)
      call allocation_error(error, stat, trim(pattern_text(n, nd)))
      if (allocated(error)) return
      pat%mq = 1.0_dp
      kq = matmul(transpose(pat%tm), matmul(k, pat%tm))
      cq = matmul(transpose(pat%tm), matmul(c, pat%tm))
      kq = 0.5_dp*(kq + transpose(kq))
      cq = 0.5_dp*(cq + transpose(cq))
      do i = 1, n
         mr(i) = mass(i)*influence_of(model, i)
      end do
      pat%lq = matmul(mr, pat%tm)
      do d = 1, nd
         col = 0.0_dp
         call add_device(model, d, 1.0_dp, col)
         pat%tb(:, d) = matmul(col, pat%tm)
      end do
   end subroutine general_reduced

   !> A general pattern's force map (pinv set): F = fq q + fp p + fag ag + f0 with
   !> fq = pinv (M T Kt - K T), fp = pinv (M T Ct - C T), fag = -pinv (M r - M T lq).
   subroutine general_force_map(model, mass, k, c, pat, error)
      type(model_type), intent(in) :: model         !! the model
      real(dp), intent(in) :: mass(:), k(:, :), c(:, :) !! structure
      type(pattern_type), intent(inout) :: pat      !! the pattern
      type(error_type), allocatable, intent(out) :: error !! no memory
      real(dp), allocatable :: mt(:, :), rr(:)
      integer :: n, i, r, stat

      n = size(mass)
      allocate (mt(n, pat%nq), rr(n), stat=stat)
      call allocation_error(error, stat, trim(pattern_text(n, model%n_devices)))
      if (allocated(error)) return
      do i = 1, n
         mt(i, :) = mass(i)*pat%tm(i, :)
      end do
      pat%fq = matmul(pat%pinv, matmul(mt, pat%kt) - matmul(k, pat%tm))
      pat%fp = matmul(pat%pinv, matmul(mt, pat%ct) - matmul(c, pat%tm))
      rr = matmul(mt, pat%lq)
      do i = 1, n
         rr(i) = mass(i)*influence_of(model, i) - rr(i)
      end do
      pat%fag = -matmul(pat%pinv, rr)
      do r = 1, pat%ns
         pat%wf(r) = sum(abs(pat%fq(r, :))*pat%wq) + sum(abs(pat%fp(r, :))*pat%wp)
      end do
   end subroutine general_force_map

   !> f0 = pinv fn: the sticking devices' forces of a net load on the pattern's DOFs.
   pure subroutine pinv_times(pat, fn, f0)
      type(pattern_type), intent(in) :: pat  !! the pattern
      real(dp), intent(in) :: fn(:)          !! the load [N], one per DOF
      real(dp), intent(out) :: f0(:)         !! the forces [N], one per sticking device
      integer :: r, i

      do r = 1, pat%ns
         f0(r) = 0.0_dp
         do i = 1, size(fn)
            f0(r) = f0(r) + pat%pinv(r, i)*fn(i)
         end do
      end do
   end subroutine pinv_times

end module fd_phase_pattern
