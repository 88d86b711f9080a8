!> Modal damping: C = sum_k (2 xi_k w_k / m_k) (M phi_k)(M phi_k)' over the kept lowest
!> modes phi_k of the stuck system (fd_matrices' natural_modes, system_stuck: every device
!> that links its nodes when stuck a rigid link, a hysteretic device its sticking spring),
!> m_k = phi_k' M phi_k. Each kept mode then has the damping ratio xi_k, the modes above
!> none. C is kept as the factors U = M Phi (n x kept) and d_k = 2 xi_k w_k / m_k: no n x n
!> matrix beyond modes_dense_dofs DOFs, whose modes are found by subspace iteration.
!> docs/theory.md, "Modal damping".
module fd_modal_damping
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error, fmt_int, stat_no_memory
   use fd_model, only: model_type, system_stuck
   use fd_names, only: max_default_modal_modes
   use fd_matrices, only: modes_type, natural_modes, natural_modes_sparse, stiffness_matrix, modes_dense_dofs, &
                          modes_flexible
   implicit none
   private

   public :: modal_damping_basis

contains

   !> model%modal_u and model%modal_d from model%modal_xi (one ratio for every kept mode, or
   !> one per kept mode) and model%modal_modes (0: as many as ratios given when more than
   !> one, else every mode of the stuck system up to max_default_modal_modes). The error
   !> names the variable of &damping at fault (more ratios or modes than the system has, a
   !> rigid-body mode among the kept ones).
   subroutine modal_damping_basis(model, error)
      type(model_type), intent(inout) :: model            !! its modal_xi, modal_modes; gets modal_u, modal_d
      type(error_type), allocatable, intent(out) :: error !! why the basis cannot be made
      type(modes_type) :: modes
      real(dp), allocatable :: k(:, :), c(:, :)
      integer :: n, nx, want, r, j, stat

      n = model%n_dof
      nx = size(model%modal_xi)
      want = model%modal_modes
      if (want == 0 .and. nx > 1) want = nx
      if (want == 0) want = min(n, max_default_modal_modes)
      if (n > modes_dense_dofs) then
         call natural_modes_sparse(model, 0.0_dp, 0.0_dp, system_stuck, want, modes, error)
      else
         allocate (k(n, n), c(n, n), stat=stat)
         if (stat /= 0) then
            call fatal_error(error, "not enough memory for the modes of "//trim(fmt_int(n))//" DOFs", stat_no_memory)
            return
         end if
         c = 0.0_dp
         call stiffness_matrix(model, k)
         call natural_modes(model, k, c, system_stuck, want, modes, error)
      end if
      if (allocated(error)) then
         error%message = "damping_type = 'modal': the modes of the stuck system: "//error%message
         return
      end if
      if (modes%status /= modes_flexible) then
         call fatal_error(error, "damping_type = 'modal' needs modes of finite period, but the stuck system "// &
                          trim(merge("has a rigid-body mode          ", "has no free DOF                ", &
                                     modes%nq > 0))//": add springs to the table")
         return
      end if
      if (nx > modes%nq) then
         call fatal_error(error, "xi has "//trim(fmt_int(nx))//" values, more than the "//trim(fmt_int(modes%nq))// &
                          " modes of the stuck system: give one ratio for every mode or one per kept mode")
         return
      end if
      if (model%modal_modes > modes%nq) then
         call fatal_error(error, "modal_modes = "//trim(fmt_int(model%modal_modes))//" is invalid: must be <= "// &
                          trim(fmt_int(modes%nq))//", the number of modes of the stuck system")
         return
      end if
      r = modes%n
      if (nx > 1 .and. nx /= r) then
         call fatal_error(error, "xi has "//trim(fmt_int(nx))//" values for "//trim(fmt_int(r))// &
                          " kept modes (modal_modes): give one ratio for every mode or one per kept mode")
         return
      end if
      allocate (model%modal_u(n, r), model%modal_d(r), stat=stat)
      if (stat /= 0) then
         call fatal_error(error, "not enough memory for the modal damping of "//trim(fmt_int(n))//" DOFs and "// &
                          trim(fmt_int(r))//" modes", stat_no_memory)
         return
      end if
      do j = 1, r
         model%modal_u(:, j) = model%mass*modes%shape(:, j)
         model%modal_d(j) = 2.0_dp*model%modal_xi(min(j, nx))*sqrt(modes%omega2(j))/ &
                            sum(model%mass*modes%shape(:, j)**2)
      end do
      model%modal_modes = r
   end subroutine modal_damping_basis

end module fd_modal_damping
