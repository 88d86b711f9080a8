!> Structures for the unit tests of the Moreau-Jean kernels, with their dense matrices as
!> the independent reference: a shear chain (devices in every storey) and a two-column frame
!> (beams between the columns, devices in one column and diagonal devices that close loops),
!> with reproducible random masses, stiffnesses and slip loads.
module test_fd_mj_models
   use fd_kinds, only: dp
   implicit none
   private

   public :: mj_model, rng_type, uniform, chain_model, frame_model, dense_w, dense_reduced, dense_b

   !> Park-Miller minimal standard generator: reproducible on every platform.
   type :: rng_type
      integer(8) :: s = 1
   end type rng_type

   !> Masses, springs and devices (node 0 = the table).
   type :: mj_model
      integer :: n = 0
      real(dp), allocatable :: mass(:)
      integer, allocatable :: si(:), sj(:), di(:), dj(:)
      real(dp), allocatable :: sk(:), pmu(:)
   end type mj_model

contains

   function uniform(rng, a, b) result(x)
      type(rng_type), intent(inout) :: rng
      real(dp), intent(in) :: a, b
      real(dp) :: x

      rng%s = mod(16807_8*rng%s, 2147483647_8)
      x = a + (b - a)*real(rng%s, dp)/2147483647.0_dp
   end function uniform

   !> n storeys: spring and device between storey i and i - 1 (storey 0: the table).
   subroutine chain_model(rng, n, m)
      type(rng_type), intent(inout) :: rng
      integer, intent(in) :: n
      type(mj_model), intent(out) :: m
      integer :: i

      m%n = n
      allocate (m%mass(n), m%sk(n), m%pmu(n))
      m%si = [(i, i=1, n)]
      m%sj = [(i - 1, i=1, n)]
      m%di = m%si
      m%dj = m%sj
      do i = 1, n
         m%mass(i) = uniform(rng, 0.5_dp, 2.0_dp)
         m%sk(i) = uniform(rng, 100.0_dp, 1000.0_dp)
         m%pmu(i) = uniform(rng, 0.2_dp, 2.0_dp)
      end do
   end subroutine chain_model

   !> Two columns of nf floors (column A nodes 1..nf, column B nf+1..2 nf): column springs,
   !> beams A_i - B_i, devices in column A between floors (none to the table) and diagonal
   !> devices A_i - B_(i+1) every other floor (closed loops with the beams and columns).
   subroutine frame_model(rng, nf, m)
      type(rng_type), intent(inout) :: rng
      integer, intent(in) :: nf
      type(mj_model), intent(out) :: m
      integer :: i, k

      m%n = 2*nf
      allocate (m%mass(2*nf))
      do i = 1, 2*nf
         m%mass(i) = uniform(rng, 0.5_dp, 2.0_dp)
      end do
      m%si = [(i, i=1, nf), (nf + i, i=1, nf), (i, i=1, nf)]
      m%sj = [(i - 1, i=1, nf), 0, (nf + i - 1, i=2, nf), (nf + i, i=1, nf)]
      allocate (m%sk(size(m%si)))
      do k = 1, size(m%sk)
         m%sk(k) = uniform(rng, 100.0_dp, 1000.0_dp)
      end do
      m%di = [(i, i=2, nf), (i, i=1, nf - 1, 2)]
      m%dj = [(i - 1, i=2, nf), (nf + i + 1, i=1, nf - 1, 2)]
      allocate (m%pmu(size(m%di)))
      do k = 1, size(m%pmu)
         m%pmu(k) = uniform(rng, 0.2_dp, 2.0_dp)
      end do
   end subroutine frame_model

   !> W = alpha M + beta K, dense.
   subroutine dense_w(m, alpha, beta, w)
      type(mj_model), intent(in) :: m
      real(dp), intent(in) :: alpha, beta
      real(dp), intent(out) :: w(:, :)
      integer :: s, i, j

      w = 0.0_dp
      do i = 1, m%n
         w(i, i) = alpha*m%mass(i)
      end do
      do s = 1, size(m%si)
         i = m%si(s)
         j = m%sj(s)
         w(i, i) = w(i, i) + beta*m%sk(s)
         if (j > 0) then
            w(j, j) = w(j, j) + beta*m%sk(s)
            w(i, j) = w(i, j) - beta*m%sk(s)
            w(j, i) = w(j, i) - beta*m%sk(s)
         end if
      end do
   end subroutine dense_w

   !> T' W T for groups grp (0: the table's), dense nr x nr.
   subroutine dense_reduced(grp, nr, w, wr)
      integer, intent(in) :: grp(0:)
      integer, intent(in) :: nr
      real(dp), intent(in) :: w(:, :)
      real(dp), allocatable, intent(out) :: wr(:, :)
      integer :: i, j

      allocate (wr(nr, nr))
      wr = 0.0_dp
      do j = 1, size(w, 2)
         do i = 1, size(w, 1)
            if (grp(i) > 0 .and. grp(j) > 0) wr(grp(i), grp(j)) = wr(grp(i), grp(j)) + w(i, j)
         end do
      end do
   end subroutine dense_reduced

   !> B = [b_d], n x number of devices.
   subroutine dense_b(m, b)
      type(mj_model), intent(in) :: m
      real(dp), allocatable, intent(out) :: b(:, :)
      integer :: d

      allocate (b(m%n, size(m%di)))
      b = 0.0_dp
      do d = 1, size(m%di)
         b(m%di(d), d) = 1.0_dp
         if (m%dj(d) > 0) b(m%dj(d), d) = -1.0_dp
      end do
   end subroutine dense_b

end module test_fd_mj_models
