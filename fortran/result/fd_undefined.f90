!> The summary values that can be undefined, and why: written as JSON null (never as 0, a
!> number a script would use), printed by the executable as "not defined (why)". The keys,
!> and when each is null, are listed in docs/namelist.md ("Undefined values"); the tests and
!> the fuzz campaign read that list.
!>
!> Scalars (undefined_why): period_stuck_s and xi_stuck (the stuck system has no period),
!> omega_max_rad_s and omega_max_dt1 (no step: the event-driven technique), energy_residual_ratio
!> (no energy passed through the structure), excitation_frequency_Hz (not a harmonic table
!> motion), mu_unconverged_s (no unconverged step), peak_base_shear_time_s (the base shear
!> stayed 0). Items of per-DOF, per-device, per-storey and per-mode lists (the masks):
!> a rigid-body mode's period and damping ratio, a drift ratio without a storey height, and
!> the time of a peak that stayed 0.
module fd_undefined
   use fd_kinds, only: dp
   use fd_result, only: result_type, run_setup, setup_of
   use fd_names, only: excitation_harmonic
   implicit none
   private

   public :: undefined_why

   !> Length of a reason.
   integer, parameter, public :: why_len = 96

contains

   !> Why the summary's scalar `key` is undefined for the result `res`: blank when it is
   !> defined (and for a key that is never undefined).
   pure function undefined_why(res, key) result(why)
      type(result_type), intent(in) :: res   !! the result of a run
      character(len=*), intent(in) :: key    !! a summary key
      character(len=why_len) :: why          !! the reason, or blank
      type(run_setup) :: setup

      why = ''
      select case (key)
      case ('period_stuck_s', 'xi_stuck')
         ! the paper's stuck system: every device a rigid link, also a hysteretic one
         setup = setup_of(res)
         if (.not. (setup%period_stuck > 0.0_dp)) &
            why = 'with every device a rigid link the structure has no free DOF or a rigid-body mode'
      case ('omega_max_rad_s', 'omega_max_dt1')
         if (.not. res%mode_checked) why = 'the event-driven technique takes no step dt1'
      case ('energy_residual_ratio')
         if (.not. (res%e_through > 0.0_dp)) why = 'no energy passed through the structure'
      case ('excitation_frequency_Hz')
         if (res%eng%excitation /= excitation_harmonic) why = 'not a harmonic table motion'
      case ('mu_unconverged_s')
         if (res%mu_unconverged == 0) why = 'no step left a speed-dependent mu unconverged'
      case ('peak_base_shear_time_s')
         if (.not. allocated(res%eng%peak_shear)) then
            why = 'no base shear'
         else if (res%eng%peak_shear(0) == 0.0_dp) then
            why = 'the base shear stayed 0'
         end if
      end select
   end function undefined_why

end module fd_undefined
