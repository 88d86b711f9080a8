!> Public API of the frictiondyn library: read a deck, run it, write its outputs.
module frictiondyn
   use fd_kinds, only: dp
   use fd_error, only: error_type, fatal_error
   use fd_model, only: model_type, integration_type, device_type
   use fd_excitation, only: excitation_type
   use fd_result, only: result_type
   use fd_deck, only: run_config, read_deck, read_deck_string
   use fd_technique, only: run_technique
   use fd_result, only: history_shape, check_finite
   use fd_output, only: output_type, write_outputs, output_paths, temp_output_paths, summary_json, &
                        history_header, write_output_files
   implicit none
   private

   public :: dp, error_type, model_type, integration_type, device_type, excitation_type
   public :: result_type, run_config, output_type
   public :: read_deck, read_deck_string, run_config_solve, run_deck, shape_of
   public :: output_paths, temp_output_paths, summary_json, history_header
   public :: write_outputs, write_output_files

contains

   !> Run the analysis a configuration defines (no files written) with the technique of
   !> its &integration: 'newmark' (the velocity and hysteretic laws) or 'event_driven'
   !> (exact Coulomb friction); an error for anything that technique cannot integrate.
   !> A solver's error names the deck.
   subroutine run_config_solve(cfg, res, error)
      type(run_config), intent(in) :: cfg                 !! model, excitation, settings
      type(result_type), intent(out) :: res               !! histories and summary
      type(error_type), allocatable, intent(out) :: error !! failure of the solver
      call run_technique(cfg%model, cfg%exc, cfg%opts, res, error)
      if (allocated(error)) return
      ! no null in a summary, no NaN in a history: a quantity that overflowed is an error
      call check_finite(res, error)
   end subroutine run_config_solve

   !> Columns and samples of the history the configuration's run produces.
   pure subroutine shape_of(cfg, ncol, nout)
      type(run_config), intent(in) :: cfg   !! model, excitation, settings
      integer, intent(out) :: ncol          !! columns
      integer, intent(out) :: nout          !! samples
      integer :: nsteps, every
      call history_shape(cfg%model, cfg%exc, cfg%opts, ncol, nout, nsteps, every)
   end subroutine shape_of

   !> Read a deck, run it and write its outputs.
   subroutine run_deck(path, cfg, res, error)
      character(len=*), intent(in) :: path                !! deck file
      type(run_config), intent(out) :: cfg                !! what the deck defines
      type(result_type), intent(out) :: res               !! histories and summary
      type(error_type), allocatable, intent(out) :: error !! bad deck, solver or output failure
      call read_deck(path, cfg, error)
      if (allocated(error)) return
      call run_config_solve(cfg, res, error)
      if (allocated(error)) return
      call write_outputs(cfg%out, cfg%model, res, path, record=cfg%record, error=error)
      if (allocated(error)) error%message = path//": "//error%message
   end subroutine run_deck

end module frictiondyn
