!> The library's layers in one module: the deck reader, the run of a configuration, the output
!> writer and the types they share, for the session (fd_session, the library's public API: one
!> deck read once, solved, queried and written) and the executable (fortran/app/main.f90).
module frictiondyn
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error
   use fd_model, only: model_type, integration_type, device_type
   use fd_excitation, only: excitation_type
   use fd_result, only: result_type
   use fd_deck, only: run_config, read_deck, read_deck_string
   use fd_technique, only: run_technique
   use fd_result, only: history_shape, check_finite, nonfinite_history_error
   use fd_output, only: output_type, write_outputs, output_paths, temp_output_paths, summary_json, &
                        history_header, write_output_files
   use fd_run_control, only: run_control, select_history, stat_cancelled
   implicit none
   private

   public :: dp, error_type, model_type, integration_type, device_type, excitation_type
   public :: result_type, run_config, output_type, run_control, select_history, stat_cancelled
   public :: read_deck, read_deck_string, run_config_solve, shape_of
   public :: output_paths, temp_output_paths, summary_json, history_header
   public :: write_outputs, write_output_files

contains

   !> Run the analysis a configuration defines (no files written) with the technique of
   !> its &integration: 'newmark' (the velocity and hysteretic laws) or 'event_driven'
   !> (exact Coulomb friction); an error for anything that technique cannot integrate.
   !> A value that is not finite is an error (check_finite), in rows the control sent only to
   !> its buffer or history file too (the observer notes the first one): the same message
   !> whether the history is kept, streamed or in a buffer.
   subroutine run_config_solve(cfg, res, error, ctl)
      type(run_config), intent(in) :: cfg                 !! model, excitation, settings
      type(result_type), intent(out) :: res               !! histories and summary
      type(error_type), allocatable, intent(out) :: error !! failure of the solver, a value not finite
      type(run_control), intent(inout), target, optional :: ctl !! history selection and
                                                          !! destinations, stop, progress
      call run_technique(cfg%model, cfg%exc, cfg%opts, res, error, ctl, cfg%exc2, cfg%exc3)
      if (allocated(error)) return
      ! no null in a summary, no NaN in a history: a quantity that overflowed is an error
      call check_finite(res, error)
      if (allocated(error) .or. .not. present(ctl)) return
      ! rows that went only to the caller's buffer or the history file
      if (ctl%bad_column > 0) call nonfinite_history_error(res%names(ctl%bad_column), ctl%bad_time, &
                                                           ctl%bad_value, error)
   end subroutine run_config_solve

   !> Columns and samples of the history the configuration's run produces.
   pure subroutine shape_of(cfg, ncol, nout, n_dof_kept, n_devices_kept)
      type(run_config), intent(in) :: cfg   !! model, excitation, settings
      integer, intent(out) :: ncol          !! columns
      integer, intent(out) :: nout          !! samples
      integer, intent(in), optional :: n_dof_kept     !! DOFs in the history (default all)
      integer, intent(in), optional :: n_devices_kept !! devices in the history (default all)
      integer :: nsteps, every
      call history_shape(cfg%model, cfg%exc, cfg%opts, ncol, nout, nsteps, every, n_dof_kept, n_devices_kept)
   end subroutine shape_of

end module frictiondyn
