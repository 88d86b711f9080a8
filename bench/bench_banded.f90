!> Micro-benchmark of the effective-stiffness kernel (fd_banded): time per solve, per
!> matrix-vector product, per single-device update and per full factorization, dense
!> (dpotrf) against banded (RCM + dpbtrf + rank-one updates), for shear buildings (a spring
!> and a friction device in every storey: a chain) and braced plane frames of 4 columns.
!> Built and run by bench/banded.sh; not part of the build.
!>
!>   bench_banded [table | small | wide | calibrate | alloc N]
!>
!> table: the table of the report; small: dense against banded for n = 2..16, interleaved,
!> the best of 5 rounds (the crossover spd_dense_max_n); wide: dense against banded for
!> frames whose band is a growing fraction of n (the rule 2 (band + 1) > n); calibrate: time per column of a rank-one modification
!> and of a refactorization against the bandwidth (for the weights of the operation
!> counts); alloc N: N device changes and solves after the set-up (for valgrind's count of
!> heap allocations, which must not depend on N).
program bench_banded
   use, intrinsic :: iso_fortran_env, only: output_unit, int64
   use fd_kinds, only: dp
   use fd_error, only: error_type
   use fd_kinematics, only: pair_terms
   use fd_banded, only: spd_system, spd_setup, spd_factor, spd_update_device, spd_update_devices, &
                        spd_solve, spd_k_matvec, spd_c_matvec, spd_bandwidth, spd_dense, spd_banded, &
                        spd_auto, spd_choose, spd_rank_one, spd_refactor, spd_is_dense, spd_size
   implicit none
   character(len=32) :: mode, arg
   integer :: nalloc

   mode = 'table'
   if (command_argument_count() >= 1) call get_command_argument(1, mode)
   select case (trim(mode))
   case ('table')
      call table()
   case ('small')
      call small()
   case ('wide')
      call wide()
   case ('calibrate')
      call calibrate()
   case ('alloc')
      call get_command_argument(2, arg)
      read (arg, *) nalloc
      call alloc_run(nalloc)
   case default
      write (output_unit, '(a)') 'usage: bench_banded [table | small | wide | calibrate | alloc N]'
   end select

contains

   !> Shear building of n storeys (nx = 1) or braced frame of nx columns, n/nx floors.
   subroutine structure(n, nx, mass, si, sj, sk, di, dj)
      integer, intent(in) :: n, nx
      real(dp), allocatable, intent(out) :: mass(:), sk(:)
      integer, allocatable, intent(out) :: si(:), sj(:), di(:), dj(:)
      integer :: c, f, ny, ns, nd, below

      ny = n/nx
      allocate (mass(n), si(2*n), sj(2*n), sk(2*n), di(2*n), dj(2*n))
      ns = 0
      nd = 0
      do f = 1, ny
         do c = 1, nx
            mass(node(c, f, ny)) = 1.0e5_dp*(1.0_dp + 0.1_dp*mod(f, 3))
            below = 0
            if (f > 1) below = node(c, f - 1, ny)
            ns = ns + 1
            si(ns) = node(c, f, ny); sj(ns) = below; sk(ns) = 1.0e8_dp
            if (c < nx) then
               ns = ns + 1
               si(ns) = node(c, f, ny); sj(ns) = node(c + 1, f, ny); sk(ns) = 5.0e8_dp
               below = 0
               if (f > 1) below = node(c + 1, f - 1, ny)
               nd = nd + 1
               di(nd) = node(c, f, ny); dj(nd) = below
            else if (nx == 1) then
               nd = nd + 1
               di(nd) = node(c, f, ny); dj(nd) = below
            end if
         end do
      end do
      si = si(1:ns); sj = sj(1:ns); sk = sk(1:ns)
      di = di(1:nd); dj = dj(1:nd)
   end subroutine structure

   subroutine build(n, nx, path, method, sys, kd)
      integer, intent(in) :: n, nx, path, method
      type(spd_system), intent(out) :: sys
      real(dp), allocatable, intent(out) :: kd(:)
      real(dp), allocatable :: mass(:), sk(:)
      integer, allocatable :: si(:), sj(:), di(:), dj(:)
      type(error_type), allocatable :: error
      integer :: d

      call structure(n, nx, mass, si, sj, sk, di, dj)
      call pair_setup(sys, mass, si, sj, sk, di, dj, error, a0=0.3_dp, a1=2.0e-3_dp, path=path, &
                     method=method)
      if (allocated(error)) error stop 1
      allocate (kd(size(di)))
      do d = 1, size(kd)
         kd(d) = merge(3.0e9_dp, 0.0_dp, mod(d, 2) == 0)   ! half the devices sticking
      end do
   end subroutine build

   !> DOF of column cc, floor ff: numbered floor by floor, from the top in even columns,
   !> so that the given numbering is not banded.
   pure integer function node(cc, ff, ny)
      integer, intent(in) :: cc, ff, ny

      if (mod(cc, 2) == 1) then
         node = (cc - 1)*ny + ff
      else
         node = cc*ny + 1 - ff
      end if
   end function node

   !> Processor time of this process [s]: on a shared machine, time spent descheduled does
   !> not count.
   real(dp) function now()
      call cpu_time(now)
   end function now

   !> Seconds per call of an operation: the best of 3 blocks of reps calls, reps grown
   !> until a block takes 20 ms.
   real(dp) function per_call(sys, kd, what, budget) result(best)
      type(spd_system), intent(inout) :: sys
      real(dp), intent(inout) :: kd(:)
      character(len=*), intent(in) :: what
      real(dp), intent(in) :: budget
      type(error_type), allocatable :: error
      real(dp), allocatable :: b(:), y(:)
      real(dp) :: t0, t
      integer :: reps, r, block, d, n, nd

      n = spd_size(sys)
      nd = size(kd)
      allocate (b(n), y(n))
      b = 1.0_dp
      y = 0.0_dp
      call spd_factor(sys, 4.0e4_dp, 200.0_dp, kd, error)
      if (allocated(error)) error stop 2
      reps = 1
      best = huge(1.0_dp)
      block = 0
      do while (block < 3)
         t0 = now()
         do r = 1, reps
            select case (what)
            case ('factor')
               call spd_factor(sys, 4.0e4_dp, 200.0_dp, kd, error)
            case ('solve')
               call spd_solve(sys, b, error)
            case ('matvec')
               call spd_k_matvec(sys, b, y, 1.0_dp, 0.0_dp)
            case ('update')
               ! one device changes phase: positions spread over the whole ordering
               d = 1 + mod(mod(r, 100003)*7919, nd)
               kd(d) = merge(0.0_dp, 3.0e9_dp, kd(d) > 0.0_dp)
               call spd_update_device(sys, d, kd(d), error)
            end select
            if (allocated(error)) then
               write (output_unit, "(a)") error%message
               error stop 3
            end if
         end do
         t = now() - t0
         if (t < budget .and. block == 0) then
            reps = reps*4
            cycle
         end if
         best = min(best, t/reps)
         block = block + 1
      end do
   end function per_call

   subroutine table()
      integer, parameter :: sizes(*) = [2, 3, 4, 5, 6, 8, 10, 15, 20, 30, 50, 100, 300, 1000, 3000, 10000]
      integer, parameter :: dense_max = 3000
      type(spd_system) :: sys
      real(dp), allocatable :: kd(:)
      real(dp) :: t(4, 2)
      integer :: i, n, path, shape, nx, kb
      character(len=*), parameter :: hdr = '(a6, a5, a12, 2a9, a12, " |", a11, 2a9, a10, a7)'
      character(len=*), parameter :: row = '(i6, i5, f12.3, 2f9.3, f12.2, " |", f11.3, 2f9.3, f10.2, a7)'

      do shape = 1, 2
         nx = merge(1, 4, shape == 1)
         if (shape == 1) then
            write (output_unit, '(/a)') 'shear building: a spring and a friction device in every storey (chain)'
         else
            write (output_unit, '(/a)') 'braced frame, 4 columns: a friction brace in every bay'
         end if
         write (output_unit, '(a)') 'microseconds per call (processor time, best of 3); update = one device changes '// &
            'phase (spd_choose); step: the faster for solve + 2 matvecs'
         write (output_unit, hdr) 'n', 'band', 'dense:solve', 'matvec', 'update', 'factor', &
            'band:solve', 'matvec', 'update', 'factor', 'step'
         do i = 1, size(sizes)
            n = sizes(i)
            if (shape == 2) n = 4*max(1, sizes(i)/4)
            if (shape == 2 .and. sizes(i) < 10) cycle
            t = -1.0_dp
            kb = 0
            do path = spd_dense, spd_banded
               if (path == spd_dense .and. n > dense_max) cycle
               call build(n, nx, path, spd_choose, sys, kd)
               if (path == spd_banded) kb = spd_bandwidth(sys)
               t(1, path) = 1.0e6_dp*per_call(sys, kd, 'solve', 0.02_dp)
               t(2, path) = 1.0e6_dp*per_call(sys, kd, 'matvec', 0.02_dp)
               t(3, path) = 1.0e6_dp*per_call(sys, kd, 'update', 0.02_dp)
               t(4, path) = 1.0e6_dp*per_call(sys, kd, 'factor', 0.02_dp)
            end do
            write (output_unit, row) n, kb, t(:, 1), t(:, 2), faster(t)
         end do
      end do
      call build(2, 1, spd_auto, spd_choose, sys, kd)
      write (output_unit, '(/a, l1)') 'spd_auto stores n = 2 dense: ', spd_is_dense(sys)
   end subroutine table

   !> Dense against banded for small chains, each measured 5 times interleaved (best kept):
   !> the crossover.
   subroutine small()
      type(spd_system) :: sys
      real(dp), allocatable :: kd(:)
      real(dp) :: t(4, 2)
      integer :: n, path, round, k
      character(len=6), parameter :: what(4) = ['solve ', 'matvec', 'update', 'factor']

      write (output_unit, '(a)') 'shear building (chain), microseconds per call, best of 5 interleaved rounds (processor time)'
      write (output_unit, '(a6, 4a11, " |", 4a11, a9)') 'n', 'dense:solve', 'matvec', 'update', 'factor', &
         'band:solve', 'matvec', 'update', 'factor', 'faster'
      do n = 2, 16
         t = huge(1.0_dp)
         do round = 1, 5
            do path = spd_dense, spd_banded
               call build(n, 1, path, spd_choose, sys, kd)
               do k = 1, 4
                  t(k, path) = min(t(k, path), 1.0e6_dp*per_call(sys, kd, trim(what(k)), 0.01_dp))
               end do
            end do
         end do
         write (output_unit, '(i6, 4f11.3, " |", 4f11.3, a9)') n, t(:, 1), t(:, 2), faster(t)
      end do
   end subroutine small

   !> Dense against banded for graphs whose band after RCM is a growing fraction of n: a
   !> chain of n = 64 or 256 DOFs plus extra springs between random pairs (devices on the
   !> chain's storeys).
   subroutine wide()
      integer, parameter :: ns(2) = [64, 256]
      type(spd_system) :: sys
      type(error_type), allocatable :: error
      real(dp), allocatable :: kd(:), mass(:), sk(:), r(:)
      integer, allocatable :: si(:), sj(:), di(:), dj(:)
      real(dp) :: t(4, 2)
      integer :: i, n, extra, path, k, kb, e
      character(len=6), parameter :: what(4) = ['solve ', 'matvec', 'update', 'factor']

      write (output_unit, '(a)') 'chain + random extra springs; microseconds per call (processor time)'
      write (output_unit, '(a5, a6, a5, a9, 4a9, " |", 4a9, a7)') 'n', 'extra', 'band', '2(b+1)/n', 'd:solve', &
         'matvec', 'update', 'factor', 'b:solve', 'matvec', 'update', 'factor', 'step'
      do i = 1, 2
         n = ns(i)
         extra = 0
         do while (extra <= 4*n)
            call structure(n, 1, mass, si, sj, sk, di, dj)
            allocate (r(2*extra))
            call random_number(r)
            si = [si, (1 + int(r(2*e - 1)*n), e=1, extra)]
            sj = [sj, (1 + int(r(2*e)*n), e=1, extra)]
            sk = [sk, (1.0e7_dp, e=1, extra)]
            do e = size(si) - extra + 1, size(si)
               if (si(e) == sj(e)) sj(e) = 0
            end do
            deallocate (r)
            allocate (kd(size(di)))
            kd = 0.0_dp
            kd(::2) = 3.0e9_dp
            t = huge(1.0_dp)
            do path = spd_dense, spd_banded
               call pair_setup(sys, mass, si, sj, sk, di, dj, error, a0=0.3_dp, a1=2.0e-3_dp, path=path)
               if (allocated(error)) error stop 6
               if (path == spd_banded) kb = spd_bandwidth(sys)
               do k = 1, 4
                  t(k, path) = 1.0e6_dp*per_call(sys, kd, trim(what(k)), 0.01_dp)
               end do
            end do
            write (output_unit, '(i5, i6, i5, f9.2, 4f9.3, " |", 4f9.3, a7)') n, extra, kb, 2.0_dp*(kb + 1)/n, &
               t(:, 1), t(:, 2), faster(t)
            deallocate (kd)
            extra = max(1, 4*extra)
         end do
      end do
   end subroutine wide

   !> Which storage is faster for a step (solve + 2 matvecs).
   character(len=6) function faster(t)
      real(dp), intent(in) :: t(4, 2)
      real(dp) :: step(2)

      step = t(1, :) + 2.0_dp*t(2, :)
      if (t(1, 1) < 0.0_dp) then
         faster = 'band'
      else if (step(1) < step(2)) then
         faster = 'dense'
      else
         faster = 'band'
      end if
   end function faster

   !> Per-column time of a rank-one modification from column 1 and of a refactorization
   !> from column 1, against the bandwidth, on n = 2000.
   subroutine calibrate()
      integer, parameter :: widths(*) = [1, 2, 4, 8, 16]
      type(spd_system) :: sys
      real(dp), allocatable :: kd(:)
      real(dp) :: tu, tf, cols
      integer :: i, nx, n, kb

      write (output_unit, '(a)') 'nanoseconds per column: rank-one modification (per column it touched), '// &
         'refactorization (full); c0 = 0.01, c1 = 0: no decay'
      write (output_unit, '(a5, 3a12)') 'band', 'update', 'refactor', 'ratio'
      do i = 1, size(widths)
         nx = widths(i)
         n = 2000*nx
         if (nx > 1) n = nx*(4000/nx)
         call build(n, nx, spd_banded, spd_rank_one, sys, kd)
         kb = spd_bandwidth(sys)
         tf = per_call(sys, kd, 'factor', 0.05_dp)
         tu = per_updates_from_first(sys, kd, cols)
         write (output_unit, '(i5, 2f12.2, f12.3, a, f8.0)') kb, 1.0e9_dp*tu/cols, 1.0e9_dp*tf/n, &
            (tf/n)/(tu/cols), '   columns per update:', cols
      end do
   end subroutine calibrate

   !> Seconds per rank-one modification of the device at the first column of the ordering.
   real(dp) function per_updates_from_first(sys, kd, cols) result(best)
      type(spd_system), intent(inout) :: sys
      real(dp), intent(inout) :: kd(:)
      real(dp), intent(out) :: cols      !! columns touched per update
      type(error_type), allocatable :: error
      real(dp) :: t0, t, cur
      integer :: r, reps, d, k, block
      integer(int64) :: c0

      call spd_factor(sys, 0.01_dp, 0.0_dp, kd, error)
      ! the device whose first column is the lowest: try each once, keep the slowest
      d = 1
      cur = 0.0_dp
      do k = 1, size(kd)
         t0 = now()
         kd(k) = kd(k) + 1.0e6_dp
         call spd_update_device(sys, k, kd(k), error)
         t = now() - t0
         if (t > cur) then
            cur = t
            d = k
         end if
      end do
      reps = 1
      best = huge(1.0_dp)
      block = 0
      do while (block < 3)
         c0 = sys%stats%update_columns
         t0 = now()
         do r = 1, reps
            kd(d) = kd(d) + merge(1.0e6_dp, -1.0e6_dp, mod(r, 2) == 1)
            call spd_update_device(sys, d, kd(d), error)
            if (allocated(error)) error stop 4
         end do
         t = now() - t0
         if (t < 0.05_dp .and. block == 0) then
            reps = reps*4
            cycle
         end if
         best = min(best, t/reps)
         cols = real(sys%stats%update_columns - c0, dp)/reps
         block = block + 1
      end do
   end function per_updates_from_first

   !> N device changes, solves and products after the set-up (valgrind counts allocations).
   subroutine alloc_run(nsteps)
      integer, intent(in) :: nsteps
      type(spd_system) :: sys
      type(error_type), allocatable :: error
      real(dp), allocatable :: kd(:), b(:), y(:)
      integer :: step, d, path, method

      do path = spd_dense, spd_banded
         do method = spd_choose, spd_refactor
            call build(60, 1, path, method, sys, kd)
            allocate (b(60), y(60))
            b = 1.0_dp
            call spd_factor(sys, 4.0e4_dp, 200.0_dp, kd, error)
            do step = 1, nsteps
               d = 1 + mod(step*7919, size(kd))
               kd(d) = merge(0.0_dp, 3.0e9_dp, kd(d) > 0.0_dp)
               call spd_update_device(sys, d, kd(d), error)
               ! a device made very stiff, then released: a fallback
               kd(1 + mod(((step + 1)/2)*31, size(kd))) = 1.0e14_dp*mod(step, 2)
               call spd_update_devices(sys, kd, error)
               call spd_solve(sys, b, error)
               call spd_k_matvec(sys, b, y, 1.0_dp, 0.0_dp)
               call spd_c_matvec(sys, b, y, 1.0_dp, 1.0_dp)
               b = b/maxval(abs(b))
               if (allocated(error)) error stop 5
            end do
            call spd_factor(sys, 4.0e4_dp, 200.0_dp, kd, error)
            write (output_unit, '(a, 2i2, 6i8, i10)') 'path, method, stats:', path, method, sys%stats
            deallocate (b, y)
         end do
      end do
   end subroutine alloc_run

   !> spd_setup for devices between two nodes (di, dj; 0 = the table).
   subroutine pair_setup(sys, mass, si, sj, sk, di, dj, error, a0, a1, path, method)
      type(spd_system), intent(out) :: sys
      real(dp), intent(in) :: mass(:), sk(:)
      integer, intent(in) :: si(:), sj(:), di(:), dj(:)
      type(error_type), allocatable, intent(out) :: error
      real(dp), intent(in), optional :: a0, a1
      integer, intent(in), optional :: path, method
      integer :: ptr(size(di) + 1), dof(2*size(di))
      real(dp) :: coef(2*size(di))

      call pair_terms(di, dj, ptr, dof, coef)
      call spd_setup(sys, mass, si, sj, sk, ptr, dof, coef, error, a0=a0, a1=a1, path=path, method=method)
   end subroutine pair_setup

end program bench_banded
