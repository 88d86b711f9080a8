!> The one-step problem of Moreau-Jean time stepping for devices of any direction b_d and a
!> stiffness with entries beyond springs (K_x): the dense form, for models of tens to a
!> few hundred DOFs whose devices are coupled through general b vectors (rigid floors,
!> matrices read from files).
!>
!>   W v1 = r - B lambda,   W = alpha M + beta K,   w = B' v1,
!>   |lambda_d| <= g_d,   w_d > 0 => lambda_d = g_d,   w_d < 0 => lambda_d = -g_d.
!>
!> W is constant over a run (the step is), so it is factored once (Cholesky) with
!> Z = W^-1 B and the Delassus operator A = B' W^-1 B (symmetric positive semidefinite). A
!> step is then one solve x = W^-1 r, the box LCP of the devices' impulses
!>   -w = A lambda - B' x,   lambda in [-g, g]
!> (fd_lcp: Lemke, exact; its w is unique, and lambda too unless devices are redundant), and
!> v1 = x - Z lambda. The acceleration at the end of a step (Coulomb's law at the level of
!> accelerations, W = M) is the same problem with A_M = B' M^-1 B over the devices at rest,
!> the sliding ones carrying sigma P mu. Memory: n^2 + 2 n nd + 3 nd^2 reals.
!>
!> The banded form (`banded`, chosen by impulse_banded) holds no n x n matrix: K and the
!> factor of W in fd_banded's band storage after reverse Cuthill-McKee (W = beta (K + alpha /
!> beta M), the springs and K_x its graph), the directions as their sparse terms. A is formed
!> from nd solves at set-up; a step is x = W^-1 r, the same box LCP, and v1 = W^-1 (r - B lambda)
!> by a second solve (no n x nd Z). Memory O(n (kb + 1) + 3 nd^2 + terms); nothing allocates
!> after set-up. The two forms agree to round-off.
!>
!> A model with planar bearings (devices that name a partner) takes the friction disc of
!> each bearing in place of its components' intervals: the same problem with
!> |lambda_b| <= g_b, solved by projected block Gauss-Seidel (fd_disc_solver) from the last
!> solution; a bearing that slides at the end of a step carries P mu along its end velocity
!> in the acceleration problem. A model without bearings keeps Lemke's method.
module fd_dense_impulse
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, fmt_real, allocation_error
   use fd_model, only: model_type
   use fd_kinematics, only: add_device, device_coupling
   use fd_matrices, only: stiffness_matrix
   use fd_linalg, only: cholesky_factor, cholesky_solve
   use fd_banded, only: spd_system, spd_setup, spd_factor, spd_solve, spd_k_matvec, spd_banded, spd_bandwidth
   use fd_names, only: linear_system_dense, linear_system_banded
   use fd_lcp, only: lcp_work, lcp_info, lcp_init, box_lcp_solve, lcp_solved, lcp_status_text
   use fd_disc_solver, only: disc_gauss_seidel, disc_ok, disc_unconverged
   implicit none
   private

   public :: dense_impulse, dense_setup, dense_factor, dense_solve, dense_acceleration, dense_k_times
   public :: impulse_banded, impulse_bandwidth, banded_min_dofs

   real(dp), parameter :: tol_rel = 1.0e-10_dp    !! a relative velocity is 0 below this share of its terms
   real(dp), parameter :: tol_sweep = 1.0e-13_dp  !! bearings: the sweeps stop below this change of an
                                                  !! impulse (force), relative to the largest bound
   integer, parameter :: max_sweeps = 20000       !! bearings: the sweeps' cap (an error beyond)
   !> Fewest DOFs for which linear_system = 'auto' takes the banded form: the measured crossover
   !> of a step's cost (bench/moreau_jean_scale.py; docs/theory.md, section 12.6).
   integer, parameter :: banded_min_dofs = 12

   !> The structure's dense matrices, the devices' directions and the factored step system.
   type :: dense_impulse
      integer :: n = 0                               !! DOFs
      integer :: nd = 0                              !! devices
      real(dp), allocatable :: mass(:)               !! (n) lumped masses
      real(dp), allocatable :: k(:, :)               !! (n, n) K, springs and K_x
      real(dp), allocatable :: b(:, :)               !! (n, nd) directions b_d
      real(dp), allocatable :: wf(:, :)              !! (n, n) Cholesky factor of W
      real(dp), allocatable :: z(:, :)               !! (n, nd) W^-1 B
      real(dp), allocatable :: a(:, :)               !! (nd, nd) B' W^-1 B
      real(dp), allocatable :: am(:, :)              !! (nd, nd) B' M^-1 B
      real(dp), allocatable :: x(:)                  !! (n) work
      real(dp), allocatable :: q(:), lo(:), hi(:), zz(:), ww(:), sub(:, :) !! (nd) LCP data
      integer, allocatable :: idx(:)                 !! (nd) devices of a sub-problem
      type(lcp_work) :: lcp                          !! Lemke's workspace
      logical :: planar = .false.                    !! some devices are planar bearings' components
      integer, allocatable :: partner(:)             !! (nd) a bearing's other component, 0: none
      integer, allocatable :: psub(:)                !! (nd) partner within a sub-problem
      integer, allocatable :: pos(:)                 !! (nd) a device's place in a sub-problem
      real(dp), allocatable :: lam0(:), f0(:)        !! (nd) bearings: the last impulses, forces
      real(dp), allocatable :: gsub(:)               !! (nd) bounds of a sub-problem
      integer :: sweeps = 0                          !! bearings: Gauss-Seidel sweeps made
      integer :: factorizations = 0                  !! factorizations of W
      logical :: banded = .false.                    !! the banded form: no k, b, wf, z
      type(spd_system) :: sys                        !! banded form: K and the factor of K + c0 M
      real(dp) :: alpha = 1.0_dp, beta = 0.0_dp      !! banded form: W = alpha M + beta K
      integer, allocatable :: bptr(:), bdof(:)       !! banded form: the directions' terms
      real(dp), allocatable :: bcoef(:)              !!   (model%dev_ptr, dev_dof, dev_coef)
      real(dp), allocatable :: y(:)                  !! (n) banded form: work
      integer :: lcp_solves = 0                      !! box LCPs solved (with bearings: the problems
                                                     !! solved by block Gauss-Seidel)
   end type dense_impulse

contains

   !> Whether a model of n DOFs takes the banded form under &integration's linear_system:
   !> 'dense' never, 'banded' always, 'auto' from banded_min_dofs DOFs on.
   pure logical function impulse_banded(n, linear_system) result(banded)
      integer, intent(in) :: n                      !! DOFs
      integer, intent(in) :: linear_system          !! fd_names' linear_system_*

      banded = linear_system == linear_system_banded
      if (linear_system /= linear_system_dense .and. linear_system /= linear_system_banded) &
         banded = n >= banded_min_dofs
   end function impulse_banded

   !> The half-bandwidth of the banded form's W after ordering (-1 for the dense form).
   integer function impulse_bandwidth(di) result(kb)
      type(dense_impulse), intent(in) :: di         !! the solver (set up)

      kb = -1
      if (di%banded) kb = spd_bandwidth(di%sys)
   end function impulse_bandwidth

   !> The matrices of a model: K with its K_x, the directions B, and A_M = B' M^-1 B; dense,
   !> or in the banded form when banded is given and true.
   subroutine dense_setup(di, model, error, banded)
      type(dense_impulse), intent(out) :: di        !! the solver
      type(model_type), intent(in) :: model         !! the model
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      logical, intent(in), optional :: banded       !! the banded form (default: dense)
      integer :: n, nd, d, stat

      if (present(banded)) di%banded = banded
      n = model%n_dof
      nd = model%n_devices
      di%n = n
      di%nd = nd
      allocate (di%mass(n), di%a(nd, nd), di%am(nd, nd), di%x(n), di%q(nd), di%lo(nd), di%hi(nd), di%zz(nd), &
                di%ww(nd), di%sub(nd, nd), di%idx(nd), di%partner(nd), di%psub(nd), di%pos(nd), di%lam0(nd), &
                di%f0(nd), di%gsub(nd), stat=stat)
      call allocation_error(error, stat, trim(system_text(di)))
      if (stat /= 0) return
      di%mass = model%mass
      if (di%banded) then
         call banded_matrices(di, model, error)
      else
         call dense_matrices(di, model, error)
      end if
      if (allocated(error)) return
      do d = 1, nd
         di%partner(d) = model%dev(d)%partner
      end do
      di%planar = any(di%partner > 0)
      di%lam0 = 0.0_dp
      di%f0 = 0.0_dp
      if (nd > 0) call lcp_init(di%lcp, nd, nd, error)
   end subroutine dense_setup

   !> What the solver's system is, in the message of a failed allocation.
   pure function system_text(di) result(text)
      type(dense_impulse), intent(in) :: di         !! the solver (n, nd and the form set)
      character(len=96) :: text

      text = "the "//trim(merge("banded", "dense ", di%banded))//" Moreau-Jean system of "//trim(fmt_int(di%n))// &
             " DOFs and "//trim(fmt_int(di%nd))//" devices"
   end function system_text

   !> dense_setup's dense form: K (springs and K_x), the directions B as columns, A_M from
   !> them over the DOFs.
   subroutine dense_matrices(di, model, error)
      type(dense_impulse), intent(inout) :: di      !! the solver (dense, mass set)
      type(model_type), intent(in) :: model         !! the model
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      integer :: n, nd, d, e, stat

      n = di%n
      nd = di%nd
      allocate (di%k(n, n), di%b(n, nd), di%wf(n, n), di%z(n, nd), stat=stat)
      call allocation_error(error, stat, trim(system_text(di)))
      if (stat /= 0) return
      call stiffness_matrix(model, di%k)
      di%b = 0.0_dp
      do d = 1, nd
         call add_device(model, d, 1.0_dp, di%b(:, d))
      end do
      do e = 1, nd
         do d = 1, nd
            di%am(d, e) = sum(di%b(:, d)*di%b(:, e)/di%mass)
         end do
      end do
   end subroutine dense_matrices

   !> dense_setup's banded form: K (springs and K_x) in fd_banded's band storage, ordered by
   !> reverse Cuthill-McKee over its own graph (the devices do not enter W), the directions'
   !> sparse terms, A_M from them.
   subroutine banded_matrices(di, model, error)
      type(dense_impulse), intent(inout) :: di      !! the solver (banded, mass set)
      type(model_type), intent(in) :: model         !! the model
      type(error_type), allocatable, intent(out) :: error !! not enough memory
      integer, allocatable :: none(:)
      real(dp), allocatable :: no_coef(:)
      integer :: nd, d, e, stat

      nd = di%nd
      allocate (di%y(di%n), di%bptr(nd + 1), di%bdof(model%dev_ptr(nd + 1) - 1), &
                di%bcoef(model%dev_ptr(nd + 1) - 1), none(0), no_coef(0), stat=stat)
      call allocation_error(error, stat, trim(system_text(di)))
      if (stat /= 0) return
      di%bptr = model%dev_ptr(1:nd + 1)
      di%bdof = model%dev_dof(1:size(di%bdof))
      di%bcoef = model%dev_coef(1:size(di%bcoef))
      call spd_setup(di%sys, model%mass, model%spring_i, model%spring_j, model%spring_k, [1], none, no_coef, &
                     error, path=spd_banded, kx_i=model%kx_i, kx_j=model%kx_j, kx_v=model%kx_v)
      if (allocated(error)) return
      do e = 1, nd
         do d = 1, nd
            di%am(d, e) = device_coupling(model, d, e)
         end do
      end do
   end subroutine banded_matrices

   !> b_d' x.
   pure real(dp) function b_dot(di, d, x) result(s)
      type(dense_impulse), intent(in) :: di         !! the solver
      integer, intent(in) :: d                      !! device
      real(dp), intent(in) :: x(:)                  !! (n)
      integer :: k

      if (.not. di%banded) then
         s = dot_product(di%b(:, d), x)
         return
      end if
      s = 0.0_dp
      do k = di%bptr(d), di%bptr(d + 1) - 1
         s = s + di%bcoef(k)*x(di%bdof(k))
      end do
   end function b_dot

   !> x = x - b_d f, or x = x - b_d f / m (each DOF's mass) when per_mass.
   pure subroutine b_sub(di, d, f, x, per_mass)
      type(dense_impulse), intent(in) :: di         !! the solver
      integer, intent(in) :: d                      !! device
      real(dp), intent(in) :: f                     !! factor
      real(dp), intent(inout) :: x(:)               !! (n)
      logical, intent(in) :: per_mass               !! divide by the masses
      integer :: k, i

      if (.not. di%banded) then
         if (per_mass) then
            x = x - di%b(:, d)*(f/di%mass)
         else
            x = x - di%b(:, d)*f
         end if
         return
      end if
      do k = di%bptr(d), di%bptr(d + 1) - 1
         i = di%bdof(k)
         if (per_mass) then
            x(i) = x(i) - di%bcoef(k)*(f/di%mass(i))
         else
            x(i) = x(i) - di%bcoef(k)*f
         end if
      end do
   end subroutine b_sub

   !> x = W^-1 x in the banded form: beta (K + alpha / beta M) factored, or alpha M alone.
   subroutine w_solve(di, x, error)
      type(dense_impulse), intent(inout) :: di      !! the solver (banded, factored)
      real(dp), intent(inout), contiguous :: x(:)   !! (n) right-hand side, then solution
      type(error_type), allocatable, intent(out) :: error !! not factored

      if (di%beta > 0.0_dp) then
         call spd_solve(di%sys, x, error)
         x = x/di%beta
      else
         x = x/(di%alpha*di%mass)
      end if
   end subroutine w_solve

   !> Factor W = alpha M + beta K and form Z = W^-1 B and A = B' Z.
   subroutine dense_factor(di, alpha, beta, error)
      type(dense_impulse), intent(inout) :: di      !! the solver
      real(dp), intent(in) :: alpha, beta           !! W = alpha M + beta K (alpha > 0, beta >= 0)
      type(error_type), allocatable, intent(out) :: error !! W not positive definite
      integer :: i, d, info

      if (di%banded) then
         call banded_factor(di, alpha, beta, error)
         return
      end if
      di%wf = beta*di%k
      do i = 1, di%n
         di%wf(i, i) = di%wf(i, i) + alpha*di%mass(i)
      end do
      call cholesky_factor(di%wf, info)
      if (info /= 0) then
         call fatal_error(error, "the Moreau-Jean step matrix M + h theta C + (h theta)^2 K is not positive "// &
                          "definite (leading minor "//trim(fmt_int(info))//"): check the stiffness")
         return
      end if
      di%factorizations = di%factorizations + 1
      do d = 1, di%nd
         di%z(:, d) = di%b(:, d)
         call cholesky_solve(di%wf, di%z(:, d))
      end do
      di%a = matmul(transpose(di%b), di%z)
      di%a = 0.5_dp*(di%a + transpose(di%a))
   end subroutine dense_factor

   !> dense_factor's banded form: K + (alpha / beta) M factored in band storage (W / beta),
   !> A = B' W^-1 B from nd solves, one device's direction at a time.
   subroutine banded_factor(di, alpha, beta, error)
      type(dense_impulse), intent(inout) :: di      !! the solver
      real(dp), intent(in) :: alpha, beta           !! W = alpha M + beta K (alpha > 0, beta >= 0)
      type(error_type), allocatable, intent(out) :: error !! W not positive definite
      real(dp) :: no_kd(0)
      integer :: d, e

      di%alpha = alpha
      di%beta = beta
      if (beta > 0.0_dp) then
         call spd_factor(di%sys, alpha/beta, 0.0_dp, no_kd, error)
         if (allocated(error)) then
            error%message = "the Moreau-Jean step matrix M + h theta C + (h theta)^2 K is not positive definite: "// &
                            trim(error%message)
            return
         end if
      end if
      di%factorizations = di%factorizations + 1
      do d = 1, di%nd
         di%y = 0.0_dp
         call b_sub(di, d, -1.0_dp, di%y, .false.)
         call w_solve(di, di%y, error)
         if (allocated(error)) return
         do e = 1, di%nd
            di%a(e, d) = b_dot(di, e, di%y)
         end do
      end do
      di%a = 0.5_dp*(di%a + transpose(di%a))
   end subroutine banded_factor

   !> y = alpha K x + beta y (y is not read when beta = 0, as spd_k_matvec's: a y never set
   !> may hold a NaN, and 0 NaN is NaN).
   subroutine dense_k_times(di, x, y, alpha, beta)
      type(dense_impulse), intent(inout) :: di      !! the solver
      real(dp), intent(in), contiguous :: x(:)      !! (n)
      real(dp), intent(inout), contiguous :: y(:)   !! (n)
      real(dp), intent(in) :: alpha, beta           !! factors
      integer :: i, j
      real(dp) :: s

      if (di%banded) then
         call spd_k_matvec(di%sys, x, y, alpha, beta)
         return
      end if
      do i = 1, di%n
         s = 0.0_dp
         do j = 1, di%n
            s = s + di%k(i, j)*x(j)
         end do
         if (beta == 0.0_dp) then
            y(i) = alpha*s
         else
            y(i) = alpha*s + beta*y(i)
         end if
      end do
   end subroutine dense_k_times

   !> One step: v1 and the impulses lam of W v1 = r - B lam under Coulomb's law with bounds
   !> g; sigma the devices' statuses (0 at rest at the end of the step, +-1 sliding that
   !> way) and w their end-of-step relative velocities.
   subroutine dense_solve(di, r, g, v1, lam, w, sigma, error)
      type(dense_impulse), intent(inout) :: di      !! the solver, factored
      real(dp), intent(in) :: r(:)                  !! (n) right-hand side
      real(dp), intent(in) :: g(:)                  !! (nd) bounds of the impulses, >= 0
      real(dp), intent(out) :: v1(:)                !! (n) end-of-step velocities
      real(dp), intent(out) :: lam(:)               !! (nd) impulses
      real(dp), intent(out) :: w(:)                 !! (nd) b_d' v1
      integer, intent(out) :: sigma(:)              !! (nd) statuses
      type(error_type), allocatable, intent(out) :: error !! the LCP unsolved
      integer :: d, e, nd
      real(dp) :: sc

      nd = di%nd
      di%x = r
      if (di%banded) then
         call w_solve(di, di%x, error)
         if (allocated(error)) return
      else
         call cholesky_solve(di%wf, di%x)
      end if
      v1 = di%x
      lam = 0.0_dp
      w = 0.0_dp
      sigma = 0
      if (nd == 0) return
      if (di%planar) then
         call planar_solve(di, g, lam, error)
         if (allocated(error)) return
         call impulses_effect(di, r, lam, v1, error)
         if (allocated(error)) return
         call planar_statuses(di, v1, lam, w, sigma)
         return
      end if
      do d = 1, nd
         di%q(d) = -b_dot(di, d, di%x)
         di%lo(d) = -g(d)
         di%hi(d) = g(d)
      end do
      call lcp_step(di, di%a, nd, error)
      if (allocated(error)) return
      lam = di%zz(1:nd)
      call impulses_effect(di, r, lam, v1, error)
      if (allocated(error)) return
      do d = 1, nd
         w(d) = b_dot(di, d, v1)
         sc = abs(di%q(d))
         do e = 1, nd
            sc = sc + abs(di%a(d, e)*lam(e))
         end do
         if (abs(w(d)) > tol_rel*sc) sigma(d) = merge(1, -1, w(d) > 0.0_dp)
      end do
   end subroutine dense_solve

   !> v1 = W^-1 (r - B lam): x - Z lam in the dense form (v1 = x on entry), a second solve in
   !> the banded form.
   subroutine impulses_effect(di, r, lam, v1, error)
      type(dense_impulse), intent(inout) :: di      !! the solver, factored
      real(dp), intent(in) :: r(:)                  !! (n) right-hand side
      real(dp), intent(in) :: lam(:)                !! (nd) impulses
      real(dp), intent(inout) :: v1(:)              !! (n) W^-1 r on entry, end velocities on exit
      type(error_type), allocatable, intent(out) :: error !! not factored
      integer :: d

      if (.not. di%banded) then
         do d = 1, di%nd
            v1 = v1 - di%z(:, d)*lam(d)
         end do
         return
      end if
      di%y = r
      do d = 1, di%nd
         call b_sub(di, d, lam(d), di%y, .false.)
      end do
      call w_solve(di, di%y, error)
      v1 = di%y
   end subroutine impulses_effect

   !> The box LCP -w = a z + q over the first m entries of di%q, di%lo, di%hi: z in
   !> di%zz(1:m) on return.
   subroutine lcp_step(di, a, m, error)
      type(dense_impulse), intent(inout) :: di      !! the solver (q, lo, hi set)
      real(dp), intent(in) :: a(:, :)               !! (m, m) the operator
      integer, intent(in) :: m                      !! size
      type(error_type), allocatable, intent(out) :: error !! unsolved
      type(lcp_info) :: info

      di%lcp_solves = di%lcp_solves + 1
      call box_lcp_solve(di%lcp, a(1:m, 1:m), di%q(1:m), di%lo(1:m), di%hi(1:m), di%zz(1:m), di%ww(1:m), info)
      if (info%status /= lcp_solved) then
         call fatal_error(error, "the Moreau-Jean box LCP of "//trim(fmt_int(m))//" devices was not solved ("// &
                          trim(lcp_status_text(info%status))//", residual "//trim(fmt_real(info%residual))// &
                          "); try technique = 'newmark' with law = 'velocity'")
      end if
   end subroutine lcp_step

   !> The acceleration at the end of a step from forces f (all but friction): a sliding device
   !> (sigma /= 0) carries sigma P mu, the devices at rest the forces of the box LCP with
   !> A_M over them (they hold within P mu, or start to slide the way of their force).
   !> force: each device's force; sa: its status at the level of accelerations.
   subroutine dense_acceleration(di, f, pmu, sigma, acc, force, sa, error, wend)
      type(dense_impulse), intent(inout) :: di      !! the solver
      real(dp), intent(in) :: f(:)                  !! (n) forces but friction [N]
      real(dp), intent(in) :: pmu(:)                !! (nd) P mu [N]
      integer, intent(in) :: sigma(:)               !! (nd) statuses of the step
      real(dp), intent(out) :: acc(:)               !! (n) accelerations [m/s2]
      real(dp), intent(out) :: force(:)             !! (nd) forces [N]
      integer, intent(out) :: sa(:)                 !! (nd) 0 holding, +-1 sliding
      type(error_type), allocatable, intent(out) :: error !! the LCP unsolved
      real(dp), intent(in), optional :: wend(:)     !! (nd) bearings: the relative velocities whose
                                                    !! direction a sliding bearing's force takes
      integer :: d, e, m, a, b
      real(dp) :: sc, x

      if (di%planar .and. present(wend)) then
         call planar_acceleration(di, f, pmu, sigma, wend, acc, force, sa, error)
         return
      end if
      di%x = f
      m = 0
      do d = 1, di%nd
         force(d) = 0.0_dp
         sa(d) = sigma(d)
         if (sigma(d) /= 0) then
            force(d) = sigma(d)*pmu(d)
            call b_sub(di, d, force(d), di%x, .false.)
         else
            m = m + 1
            di%idx(m) = d
         end if
      end do
      acc = di%x/di%mass
      if (m > 0) then
         do a = 1, m
            d = di%idx(a)
            di%q(a) = -b_dot(di, d, acc)
            di%lo(a) = -pmu(d)
            di%hi(a) = pmu(d)
            do b = 1, m
               di%sub(a, b) = di%am(d, di%idx(b))
            end do
         end do
         call lcp_step(di, di%sub(1:m, 1:m), m, error)
         if (allocated(error)) return
         do a = 1, m
            d = di%idx(a)
            force(d) = di%zz(a)
            call b_sub(di, d, force(d), acc, .true.)
         end do
         do a = 1, m
            d = di%idx(a)
            x = b_dot(di, d, acc)
            sc = abs(di%q(a))
            do e = 1, m
               sc = sc + abs(di%sub(a, e)*force(di%idx(e)))
            end do
            if (abs(x) > tol_rel*sc) sa(d) = merge(1, -1, x > 0.0_dp)
         end do
      end if
   end subroutine dense_acceleration

   !> Bearings: the impulses of the step by block Gauss-Seidel from the last step's, with
   !> q = B' x (x = W^-1 r) the velocities without friction.
   subroutine planar_solve(di, g, lam, error)
      type(dense_impulse), intent(inout) :: di      !! the solver, x set
      real(dp), intent(in) :: g(:)                  !! (nd) bounds
      real(dp), intent(out) :: lam(:)               !! (nd) impulses
      type(error_type), allocatable, intent(out) :: error !! unconverged
      integer :: d

      do d = 1, di%nd
         di%q(d) = b_dot(di, d, di%x)
      end do
      lam = di%lam0
      call sweeps_solve(di, di%a, di%nd, g, di%partner, lam, error)
      if (allocated(error)) return
      di%lam0 = lam
   end subroutine planar_solve

   !> Block Gauss-Seidel (fd_disc_solver) on the first m entries of di%q: z in lam(1:m) (its
   !> start on entry); an error when it does not converge within its cap.
   subroutine sweeps_solve(di, a, m, g, partner, lam, error)
      type(dense_impulse), intent(inout) :: di      !! the solver (q set)
      real(dp), intent(in) :: a(:, :)               !! (m, m) the operator
      integer, intent(in) :: m                      !! size
      real(dp), intent(in) :: g(:)                  !! (m) bounds
      integer, intent(in) :: partner(:)             !! (m) bearings' pairs
      real(dp), intent(inout) :: lam(:)             !! (m) impulses or forces
      type(error_type), allocatable, intent(out) :: error !! unconverged, not definite
      integer :: sweeps, status
      real(dp) :: change

      call disc_gauss_seidel(a(1:m, 1:m), di%q(1:m), g(1:m), partner(1:m), tol_sweep, max_sweeps, lam(1:m), &
                             di%ww(1:m), sweeps, change, status)
      di%sweeps = di%sweeps + sweeps
      di%lcp_solves = di%lcp_solves + 1
      if (status == disc_ok) return
      if (status == disc_unconverged) then
         call fatal_error(error, "the Moreau-Jean one-step problem of "//trim(fmt_int(m))//" devices with planar "// &
                          "bearings did not converge: "//trim(fmt_int(sweeps))//" block Gauss-Seidel sweeps left a "// &
                          "change of "//trim(fmt_real(change))//" of the largest bound; try technique = 'newmark'")
      else
         call fatal_error(error, "the Moreau-Jean one-step problem of "//trim(fmt_int(m))//" devices: a planar "// &
                          "bearing's block of the Delassus operator is not positive definite (its two components "// &
                          "move together)")
      end if
   end subroutine sweeps_solve

   !> Bearings: the end-of-step relative velocities w = B' v1 and the statuses, a component
   !> sliding (its sign) when its velocity exceeds tol_rel of its terms, those of its bearing's
   !> larger component.
   pure subroutine planar_statuses(di, v1, lam, w, sigma)
      type(dense_impulse), intent(inout) :: di      !! the solver (q set)
      real(dp), intent(in) :: v1(:)                 !! (n) end velocities
      real(dp), intent(in) :: lam(:)                !! (nd) impulses
      real(dp), intent(out) :: w(:)                 !! (nd) relative velocities
      integer, intent(out) :: sigma(:)              !! (nd) statuses
      integer :: d, e, p
      real(dp) :: sc

      do d = 1, di%nd
         w(d) = b_dot(di, d, v1)
         di%zz(d) = abs(di%q(d))
         do e = 1, di%nd
            di%zz(d) = di%zz(d) + abs(di%a(d, e)*lam(e))
         end do
      end do
      do d = 1, di%nd
         p = di%partner(d)
         sc = di%zz(d)
         if (p > 0) sc = max(sc, di%zz(p))
         sigma(d) = 0
         if (abs(w(d)) > tol_rel*sc) sigma(d) = merge(1, -1, w(d) > 0.0_dp)
      end do
   end subroutine planar_statuses

   !> dense_acceleration with bearings: a bearing sliding at the end of the step (either
   !> component's status not 0) carries P mu along its end velocity wend; the devices at rest
   !> take the planar problem with A_M over them (each bearing's force in its disc).
   subroutine planar_acceleration(di, f, pmu, sigma, wend, acc, force, sa, error)
      type(dense_impulse), intent(inout) :: di      !! the solver
      real(dp), intent(in) :: f(:)                  !! (n) forces but friction [N]
      real(dp), intent(in) :: pmu(:)                !! (nd) P mu [N]
      integer, intent(in) :: sigma(:)               !! (nd) statuses of the step
      real(dp), intent(in) :: wend(:)               !! (nd) relative velocities at the end
      real(dp), intent(out) :: acc(:)               !! (n) accelerations [m/s2]
      real(dp), intent(out) :: force(:)             !! (nd) forces [N]
      integer, intent(out) :: sa(:)                 !! (nd) 0 holding, +-1 sliding
      type(error_type), allocatable, intent(out) :: error !! unconverged
      integer :: d, e, m, a, b, p
      real(dp) :: sc, x
      logical :: sliding

      di%x = f
      m = 0
      do d = 1, di%nd
         p = di%partner(d)
         force(d) = 0.0_dp
         sa(d) = sigma(d)
         sliding = sigma(d) /= 0
         if (p > 0) sliding = sliding .or. sigma(p) /= 0
         di%pos(d) = 0
         if (sliding) then
            force(d) = sigma(d)*pmu(d)
            if (p > 0) force(d) = pmu(d)*(wend(d)/hypot(wend(d), wend(p)))
            call b_sub(di, d, force(d), di%x, .false.)
         else
            m = m + 1
            di%idx(m) = d
            di%pos(d) = m
         end if
      end do
      acc = di%x/di%mass
      if (m == 0) return
      do a = 1, m
         d = di%idx(a)
         di%q(a) = b_dot(di, d, acc)
         di%gsub(a) = pmu(d)
         di%psub(a) = 0
         if (di%partner(d) > 0) di%psub(a) = di%pos(di%partner(d))
         di%zz(a) = di%f0(d)
         do b = 1, m
            di%sub(a, b) = di%am(d, di%idx(b))
         end do
      end do
      call sweeps_solve(di, di%sub, m, di%gsub, di%psub, di%zz, error)
      if (allocated(error)) return
      do a = 1, m
         d = di%idx(a)
         force(d) = di%zz(a)
         di%f0(d) = force(d)
         call b_sub(di, d, force(d), acc, .true.)
      end do
      do a = 1, m
         d = di%idx(a)
         sc = abs(di%q(a))
         do e = 1, m
            sc = sc + abs(di%sub(a, e)*force(di%idx(e)))
         end do
         di%lo(a) = sc
      end do
      do a = 1, m
         d = di%idx(a)
         x = b_dot(di, d, acc)
         sc = di%lo(a)
         if (di%psub(a) > 0) sc = max(sc, di%lo(di%psub(a)))
         if (abs(x) > tol_rel*sc) sa(d) = merge(1, -1, x > 0.0_dp)
      end do
   end subroutine planar_acceleration

end module fd_dense_impulse
