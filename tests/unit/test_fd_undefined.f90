!> Unit tests of the summary's undefined values (fd_undefined): for a result set by hand,
!> which scalar keys are undefined (written null, printed "not defined (why)") and which
!> are not; a key that is never undefined has no reason.
module test_fd_undefined
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_result, only: result_type
   use fd_names, only: excitation_harmonic, excitation_record
   use fd_undefined, only: undefined_why
   implicit none
   private

   public :: collect_undefined

contains

   subroutine collect_undefined(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("a defined result: no reason", test_defined), &
                  new_unittest("each undefined value and its reason", test_undefined) &
                  ]
   end subroutine collect_undefined

   !> A flexible stuck system, Newmark, energy through the structure, a harmonic motion, a
   !> base shear: nothing undefined.
   subroutine test_defined(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res
      character(len=24), parameter :: keys(8) = [character(len=24) :: 'period_stuck_s', 'xi_stuck', &
                                                 'omega_max_rad_s', 'omega_max_dt1', 'energy_residual_ratio', &
                                                 'excitation_frequency_Hz', 'peak_base_shear_time_s', 'peak_u_m']
      integer :: k

      res%newmark%ran = .true.
      res%newmark%setup%period_stuck = 0.3_dp
      res%mode_checked = .true.
      res%e_through = 12.0_dp
      res%eng%excitation = excitation_harmonic
      res%mu_unconverged = 1
      allocate (res%eng%peak_shear(0:1))
      res%eng%peak_shear = 5.0_dp
      do k = 1, size(keys)
         call check(error, undefined_why(res, trim(keys(k))), '', trim(keys(k)))
         if (allocated(error)) return
      end do
      call check(error, undefined_why(res, 'mu_unconverged_s'), '', 'mu_unconverged_s')
   end subroutine test_defined

   !> A rigid stuck system (period 0), the event-driven technique, no energy, a record, no
   !> unconverged step, a base shear that stayed 0: each key undefined, with its reason.
   subroutine test_undefined(error)
      type(error_type), allocatable, intent(out) :: error
      type(result_type) :: res

      res%exact%ran = .true.
      res%exact%setup%period_stuck = 0.0_dp
      res%mode_checked = .false.
      res%e_through = 0.0_dp
      res%eng%excitation = excitation_record
      res%mu_unconverged = 0
      allocate (res%eng%peak_shear(0:1))
      res%eng%peak_shear = 0.0_dp
      call expect('period_stuck_s', 'no free DOF or a rigid-body mode')
      call expect('xi_stuck', 'no free DOF or a rigid-body mode')
      call expect('omega_max_rad_s', 'event-driven technique')
      call expect('omega_max_dt1', 'event-driven technique')
      call expect('energy_residual_ratio', 'no energy passed')
      call expect('excitation_frequency_Hz', 'not a harmonic table motion')
      call expect('mu_unconverged_s', 'no step left')
      call expect('peak_base_shear_time_s', 'the base shear stayed 0')
      if (allocated(error)) return
      call check(error, undefined_why(res, 'dt1_s'), '', 'a key never undefined')
   contains
      subroutine expect(key, words)
         character(len=*), intent(in) :: key, words
         if (allocated(error)) return
         call check(error, index(undefined_why(res, key), words) > 0, key//': '//trim(undefined_why(res, key)))
      end subroutine expect
   end subroutine test_undefined

end module test_fd_undefined
