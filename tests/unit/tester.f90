!> Driver of the Fortran unit tests (test-drive): `tester` runs every suite,
!> `tester SUITE [TEST]` one suite or one test. meson registers one test per suite.
program tester
   use, intrinsic :: iso_fortran_env, only: error_unit
   use testdrive, only: run_testsuite, new_testsuite, testsuite_type, select_suite, run_selected, &
                        get_argument
   use test_fd_format, only: collect_format
   use test_fd_linalg, only: collect_linalg
   use test_fd_matrices, only: collect_matrices
   use test_fd_friction, only: collect_friction
   use test_fd_friction_laws, only: collect_friction_laws
   use test_fd_friction_planar, only: collect_friction_planar
   use test_fd_namelist, only: collect_namelist
   use test_fd_record, only: collect_record
   use test_fd_record_parse, only: collect_record_parse
   use test_fd_excitation, only: collect_excitation
   use test_fd_lcp, only: collect_lcp
   use test_fd_textio, only: collect_textio
   use test_fd_sort, only: collect_sort
   use test_fd_names, only: collect_names
   use test_fd_technique, only: collect_technique
   use test_fd_root_finder, only: collect_root_finder
   use test_fd_phase_pattern, only: collect_phase_pattern
   use test_fd_phase_decision, only: collect_phase_decision
   use test_fd_observer, only: collect_observer
   use test_fd_sha256, only: collect_sha256
   use test_fd_engineering, only: collect_engineering
   use test_fd_friction_mu, only: collect_friction_mu
   use test_fd_taylor, only: collect_taylor
   use test_fd_banded, only: collect_banded
   use test_fd_modes, only: collect_modes
   use test_fd_stream, only: collect_stream
   use test_fd_stick_groups, only: collect_stick_groups
   use test_fd_kinematics, only: collect_kinematics
   use test_fd_matrix_market, only: collect_matrix_market
   use test_fd_spectrum, only: collect_spectrum
   use test_fd_vertical_support, only: collect_vertical_support
   use test_fd_group_system, only: collect_group_system
   use test_fd_impulse_solver, only: collect_impulse_solver
   use test_fd_dense_impulse, only: collect_dense_impulse
   use test_fd_disc_solver, only: collect_disc_solver
   use test_fd_step_limits, only: collect_step_limits
   use test_fd_stick_ringing, only: collect_stick_ringing
   use test_fd_band_alternation, only: collect_band_alternation
   use test_fd_harmonic_resolution, only: collect_harmonic_resolution
   use test_fd_record_resolution, only: collect_record_resolution
   use test_fd_warnings, only: collect_warnings
   use test_fd_undefined, only: collect_undefined
   use test_fd_check, only: collect_check
   use test_fd_statistics, only: collect_statistics
   use test_fd_event_driven, only: collect_event_driven
   use test_fd_woodbury, only: collect_woodbury
   use test_fd_sparse, only: collect_sparse
   use test_fd_newmark, only: collect_newmark
   implicit none
   integer :: stat, is
   character(len=:), allocatable :: suite_name, test_name
   type(testsuite_type), allocatable :: testsuites(:)
   character(len=*), parameter :: fmt = '("#", *(1x, a))'

   stat = 0
   ! one suite a line (union-merge friendly: see .gitattributes)
   allocate (testsuites(0))
   testsuites = [testsuites, new_testsuite("format", collect_format)]
   testsuites = [testsuites, new_testsuite("linalg", collect_linalg)]
   testsuites = [testsuites, new_testsuite("matrices", collect_matrices)]
   testsuites = [testsuites, new_testsuite("friction", collect_friction)]
   testsuites = [testsuites, new_testsuite("friction_laws", collect_friction_laws)]
   testsuites = [testsuites, new_testsuite("friction_planar", collect_friction_planar)]
   testsuites = [testsuites, new_testsuite("namelist", collect_namelist)]
   testsuites = [testsuites, new_testsuite("record", collect_record)]
   testsuites = [testsuites, new_testsuite("record_parse", collect_record_parse)]
   testsuites = [testsuites, new_testsuite("excitation", collect_excitation)]
   testsuites = [testsuites, new_testsuite("lcp", collect_lcp)]
   testsuites = [testsuites, new_testsuite("textio", collect_textio)]
   testsuites = [testsuites, new_testsuite("sort", collect_sort)]
   testsuites = [testsuites, new_testsuite("names", collect_names)]
   testsuites = [testsuites, new_testsuite("technique", collect_technique)]
   testsuites = [testsuites, new_testsuite("root_finder", collect_root_finder)]
   testsuites = [testsuites, new_testsuite("phase_pattern", collect_phase_pattern)]
   testsuites = [testsuites, new_testsuite("phase_decision", collect_phase_decision)]
   testsuites = [testsuites, new_testsuite("observer", collect_observer)]
   testsuites = [testsuites, new_testsuite("sha256", collect_sha256)]
   testsuites = [testsuites, new_testsuite("engineering", collect_engineering)]
   testsuites = [testsuites, new_testsuite("friction_mu", collect_friction_mu)]
   testsuites = [testsuites, new_testsuite("taylor", collect_taylor)]
   testsuites = [testsuites, new_testsuite("banded", collect_banded)]
   testsuites = [testsuites, new_testsuite("modes", collect_modes)]
   testsuites = [testsuites, new_testsuite("stream", collect_stream)]
   testsuites = [testsuites, new_testsuite("stick_groups", collect_stick_groups)]
   testsuites = [testsuites, new_testsuite("kinematics", collect_kinematics)]
   testsuites = [testsuites, new_testsuite("matrix_market", collect_matrix_market)]
   testsuites = [testsuites, new_testsuite("spectrum", collect_spectrum)]
   testsuites = [testsuites, new_testsuite("vertical_support", collect_vertical_support)]
   testsuites = [testsuites, new_testsuite("group_system", collect_group_system)]
   testsuites = [testsuites, new_testsuite("impulse_solver", collect_impulse_solver)]
   testsuites = [testsuites, new_testsuite("dense_impulse", collect_dense_impulse)]
   testsuites = [testsuites, new_testsuite("disc_solver", collect_disc_solver)]
   testsuites = [testsuites, new_testsuite("step_limits", collect_step_limits)]
   testsuites = [testsuites, new_testsuite("stick_ringing", collect_stick_ringing)]
   testsuites = [testsuites, new_testsuite("band_alternation", collect_band_alternation)]
   testsuites = [testsuites, new_testsuite("harmonic_resolution", collect_harmonic_resolution)]
   testsuites = [testsuites, new_testsuite("record_resolution", collect_record_resolution)]
   testsuites = [testsuites, new_testsuite("warnings", collect_warnings)]
   testsuites = [testsuites, new_testsuite("undefined", collect_undefined)]
   testsuites = [testsuites, new_testsuite("check", collect_check)]
   testsuites = [testsuites, new_testsuite("statistics", collect_statistics)]
   testsuites = [testsuites, new_testsuite("event_driven", collect_event_driven)]
   testsuites = [testsuites, new_testsuite("woodbury", collect_woodbury)]
   testsuites = [testsuites, new_testsuite("sparse", collect_sparse)]
   testsuites = [testsuites, new_testsuite("newmark", collect_newmark)]

   call get_argument(1, suite_name)
   call get_argument(2, test_name)
   if (allocated(suite_name)) then
      is = select_suite(testsuites, suite_name)
      if (is > 0 .and. is <= size(testsuites)) then
         if (allocated(test_name)) then
            write (error_unit, fmt) "Suite:", testsuites(is)%name
            call run_selected(testsuites(is)%collect, test_name, error_unit, stat)
            if (stat < 0) error stop 1
         else
            write (error_unit, fmt) "Testing:", testsuites(is)%name
            call run_testsuite(testsuites(is)%collect, error_unit, stat)
         end if
      else
         write (error_unit, fmt) "Available testsuites"
         do is = 1, size(testsuites)
            write (error_unit, fmt) "-", testsuites(is)%name
         end do
         error stop 1
      end if
   else
      do is = 1, size(testsuites)
         write (error_unit, fmt) "Testing:", testsuites(is)%name
         call run_testsuite(testsuites(is)%collect, error_unit, stat)
      end do
   end if
   if (stat > 0) then
      write (error_unit, '(i0, 1x, a)') stat, "test(s) failed!"
      error stop 1
   end if
end program tester
