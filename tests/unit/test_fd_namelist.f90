!> Unit tests of the namelist lexer (fd_namelist): which lines open a group, a group's
!> assignments and their deck lines, comments, quoted strings holding '/', '!', '&' or '=',
!> groups closed by '/' or '&end', unclosed, missing, unknown and repeated groups, and the
!> messages that name the variable and value at fault.
module test_fd_namelist
   use testdrive, only: new_unittest, unittest_type, error_type, check
   use fd_kinds, only: dp
   use fd_error, only: fd_error_type => error_type
   use fd_namelist, only: deck_text, group_text, deck_from_string, load_deck, find_group, group_item, &
                          group_read_error, check_groups, group_opened, longest_string, next_read, &
                          given_elements
   implicit none
   private

   public :: collect_namelist

   character(len=*), parameter :: nl = achar(10)
   !> A deck using every feature of the lexer (line numbers in the comments).
   character(len=*), parameter :: sample = &
      "! frictiondyn deck"//nl// &                                        ! 1
      "&model"//nl// &                                                    ! 2
      "  n_dof = 2,  mass = 6.301, 2.530   ! masses [kg]"//nl// &         ! 3
      "  name = 'a/b!c=d'  title = ""it's / & here"""//nl// &             ! 4
      "/"//nl// &                                                         ! 5
      "&Friction n_devices = 1, law(1) = 'velocity', p(1)=61.81 /"//nl// & ! 6
      "&excitation"//nl// &                                               ! 7
      "  record_file = 'x.txt'"//nl// &                                   ! 8
      "  dt_record ="//nl// &                                             ! 9
      "     0.005"//nl// &                                                ! 10
      "&END"//nl// &                                                      ! 11
      "&output"//nl// &                                                   ! 12
      "  dir = 'out' /  ! closed at the end of a line"//nl// &            ! 13
      achar(9)//"&damping  ! a tab before"//nl// &                        ! 14
      "/"//nl// &                                                         ! 15
      "$springs n_springs = 0 $end   ! the legacy form"//nl              ! 16

contains

   subroutine collect_namelist(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)

      testsuite = [ &
                  new_unittest("group_opened", test_group_opened), &
                  new_unittest("items and their lines", test_items), &
                  new_unittest("quotes and comments", test_quotes), &
                  new_unittest("one-line group", test_one_line), &
                  new_unittest("closed by &end", test_end), &
                  new_unittest("not closed", test_not_closed), &
                  new_unittest("missing group", test_missing), &
                  new_unittest("unknown and repeated groups", test_check_groups), &
                  new_unittest("one item as a record", test_group_item), &
                  new_unittest("messages naming the variable", test_read_error), &
                  new_unittest("read loop finding the assignment at fault", test_next_read), &
                  new_unittest("missing deck file", test_load_missing), &
                  new_unittest("the legacy $name ... $end", test_legacy), &
                  new_unittest("nothing outside groups but comments", test_outside), &
                  new_unittest("'&' and '$' only where they open or close", test_ampersand), &
                  new_unittest("a NUL character", test_nul), &
                  new_unittest("a variable given twice", test_twice), &
                  new_unittest("an element given twice in another form", test_twice_forms), &
                  new_unittest("a comment after a separator is no value", test_comment_no_value), &
                  new_unittest("a text not closed on its line", test_open_text), &
                  new_unittest("a UTF-8 byte order mark before the first line", test_bom), &
                  new_unittest("the longest string of a variable", test_longest), &
                  new_unittest("the elements given, as the namelist reader assigns them", test_given), &
                  new_unittest("a value equal to any marker is given", test_given_extremes) &
                  ]
   end subroutine collect_namelist

   subroutine test_group_opened(error)
      type(error_type), allocatable, intent(out) :: error

      call check(error, trim(group_opened('&model')), 'model')
      if (allocated(error)) return
      call check(error, trim(group_opened('  &MODEL n_dof = 2 /')), 'model', 'lower case, text after the name')
      if (allocated(error)) return
      call check(error, trim(group_opened(achar(9)//'&damping')), 'damping', 'a tab before')
      if (allocated(error)) return
      call check(error, trim(group_opened('&output,')), 'output', 'a comma after the name')
      if (allocated(error)) return
      call check(error, trim(group_opened('&output/')), 'output', "a '/' right after the name")
      if (allocated(error)) return
      call check(error, len_trim(group_opened('&end')), 0, "'&end' closes, it does not open")
      if (allocated(error)) return
      call check(error, len_trim(group_opened('&END')), 0, "'&END' closes, it does not open")
      if (allocated(error)) return
      call check(error, len_trim(group_opened('&')), 0, "a lone '&'")
      if (allocated(error)) return
      call check(error, len_trim(group_opened("  name = '&model'")), 0, 'an assignment')
      if (allocated(error)) return
      call check(error, len_trim(group_opened('')), 0, 'an empty line')
      if (allocated(error)) return
      call check(error, len_trim(group_opened('! &model')), 0, 'a comment')
   end subroutine test_group_opened

   subroutine test_items(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found

      call deck_from_string(sample, 'sample.nml', deck)
      call check(error, size(deck%lines), 16, 'lines of the deck')
      if (allocated(error)) return
      call find_group(deck, 'model', grp, found, err)
      call check(error, found .and. .not. allocated(err), '&model found')
      if (allocated(error)) return
      call check(error, grp%first_line, 2)
      if (allocated(error)) return
      call check(error, size(grp%lines), 4, 'group lines from &model to /')
      if (allocated(error)) return
      call check(error, size(grp%items), 4, 'four assignments')
      if (allocated(error)) return
      call check(error, grp%items(1)%s, 'n_dof = 2', 'separator comma dropped')
      if (allocated(error)) return
      call check(error, grp%items(2)%s, 'mass = 6.301, 2.530', 'a list value, comment dropped')
      if (allocated(error)) return
      call check(error, all(grp%item_line == [3, 3, 4, 4]), 'deck line of each assignment')
   end subroutine test_items

   !> '/', '!', '&' and '=' inside quotes are text, not syntax.
   subroutine test_quotes(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found

      call deck_from_string(sample, 'sample.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call check(error, grp%items(3)%s, "name = 'a/b!c=d'", "'/', '!' and '=' inside single quotes")
      if (allocated(error)) return
      call check(error, grp%items(4)%s, 'title = "it''s / & here"', "a quote, '/' and '&' inside double quotes")
   end subroutine test_quotes

   !> '&Friction ... /' on one line: the name is matched in lower case, an index kept.
   subroutine test_one_line(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found

      call deck_from_string(sample, 'sample.nml', deck)
      call find_group(deck, 'friction', grp, found, err)
      call check(error, found .and. .not. allocated(err), '&Friction found as friction')
      if (allocated(error)) return
      call check(error, size(grp%items), 3, 'three assignments')
      if (allocated(error)) return
      call check(error, grp%items(1)%s, 'n_devices = 1')
      if (allocated(error)) return
      call check(error, grp%items(2)%s, "law(1) = 'velocity'", 'an indexed variable')
      if (allocated(error)) return
      call check(error, grp%items(3)%s, 'p(1)=61.81', 'no blanks around =')
      if (allocated(error)) return
      call check(error, all(grp%item_line == 6), 'all on line 6')
   end subroutine test_one_line

   !> '&END' closes a group; a value may continue on the next line.
   subroutine test_end(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found

      call deck_from_string(sample, 'sample.nml', deck)
      call find_group(deck, 'excitation', grp, found, err)
      call check(error, found .and. .not. allocated(err), '&excitation closed by &END')
      if (allocated(error)) return
      call check(error, size(grp%items), 2, 'two assignments')
      if (allocated(error)) return
      call check(error, grp%items(2)%s(1:11), 'dt_record =', 'a value on the next line')
      if (allocated(error)) return
      call check(error, trim(adjustl(grp%items(2)%s(12:))), '0.005', 'a value on the next line')
      if (allocated(error)) return
      call check(error, all(grp%item_line == [8, 9]), 'lines 8 and 9')
      if (allocated(error)) return
      ! the tab-indented group is found and closed
      call find_group(deck, 'damping', grp, found, err)
      call check(error, found .and. .not. allocated(err) .and. grp%first_line == 14, '&damping after a tab')
      if (allocated(error)) return
      call check(error, size(grp%items), 0, 'an empty group')
   end subroutine test_end

   !> A group that runs into the next group without '/' is an error naming it and its line.
   subroutine test_not_closed(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found

      call deck_from_string("&model"//nl//"  n_dof = 1 /"//nl//"&output"//nl//"  dir = 'out'"//nl// &
                            achar(9)//"&damping"//nl//"/"//nl, 'open.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call check(error, allocated(err), 'an unclosed group makes the deck unreadable')
      if (allocated(error)) return
      call check(error, index(err%message, "open.nml, group &output (line 3): not closed by '/' before line 5") > 0, &
                 err%message)
      if (allocated(error)) return
      call deck_from_string('&model'//nl//'  n_dof = 1'//nl, 'end.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call check(error, allocated(err), 'a group running to the end of the deck')
   end subroutine test_not_closed

   subroutine test_missing(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found

      call deck_from_string(sample, 'sample.nml', deck)
      call find_group(deck, 'integration', grp, found, err)
      call check(error, .not. found .and. .not. allocated(err), 'a missing group: not found, no error')
      if (allocated(error)) return
      call find_group(deck, 'end', grp, found, err)
      call check(error, .not. found, "'&END' is not a group")
   end subroutine test_missing

   subroutine test_check_groups(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(fd_error_type), allocatable :: err

      call deck_from_string(sample, 'sample.nml', deck)
      call check_groups(deck, [character(len=10) :: 'model', 'friction', 'excitation', 'output', 'damping', &
                               'springs'], err)
      call check(error, .not. allocated(err), 'every group known, once')
      if (allocated(error)) return
      call check_groups(deck, [character(len=10) :: 'model', 'friction', 'excitation', 'damping', 'springs'], err)
      call check(error, allocated(err), 'an unknown group')
      if (allocated(error)) return
      call check(error, index(err%message, 'sample.nml, line 12: unknown group &output') > 0, err%message)
      if (allocated(error)) return
      call check(error, index(err%message, '&model, &friction, &excitation, &damping, &springs') > 0, err%message)
      if (allocated(error)) return
      call deck_from_string('&model /'//nl//'&MODEL'//nl//'/'//nl, 'twice.nml', deck)
      call check_groups(deck, [character(len=10) :: 'model'], err)
      call check(error, allocated(err), 'a repeated group')
      if (allocated(error)) return
      call check(error, index(err%message, 'twice.nml, line 2: group &model appears more than once') > 0, &
                 err%message)
   end subroutine test_check_groups

   subroutine test_group_item(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found
      character(len=:), allocatable :: record

      call deck_from_string(sample, 'sample.nml', deck)
      call find_group(deck, 'friction', grp, found, err)
      call group_item(grp, 2, record)
      call check(error, record, "&friction law(1) = 'velocity' /")
   end subroutine test_group_item

   !> The reader's message becomes one that names file, group, line, variable and value.
   subroutine test_read_error(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found

      call deck_from_string('&integration'//nl//'  n1 = 20'//nl//'  nn2 = 50'//nl//'  n = 1.5x'//nl//'/'//nl, &
                            'bad.nml', deck)
      call find_group(deck, 'integration', grp, found, err)
      call group_read_error(deck, grp, 2, 'Cannot match namelist object name nn2', err)
      call check(error, allocated(err), 'an error')
      if (allocated(error)) return
      call check(error, err%message, "bad.nml, group &integration, line 3: unknown variable 'nn2' (value 50)")
      if (allocated(error)) return
      call group_read_error(deck, grp, 3, 'Bad real number in item 1 of list input', err)
      call check(error, err%message, "bad.nml, group &integration, line 4: variable 'n' has a bad value '1.5x' "// &
                 "(Bad real number in item 1 of list input)")
      if (allocated(error)) return
      call group_read_error(deck, grp, 0, 'End of file', err)
      call check(error, err%message, 'bad.nml, group &integration (line 1): cannot be read: End of file')
   end subroutine test_read_error

   !> A group read in a loop with next_read: once when it reads; else again one assignment
   !> at a time up to the one at fault, which the message names.
   subroutine test_next_read(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      integer :: n1, reads, ios
      real(dp) :: n
      character(len=512) :: msg
      logical :: found, more
      namelist /integration/ n1, n

      call deck_from_string('&integration'//nl//'  n1 = 20'//nl//'  n = 1.5'//nl//'/'//nl, 'good.nml', deck)
      call find_group(deck, 'integration', grp, found, err)
      n1 = 0; n = 0.0_dp; reads = 0
      do
         reads = reads + 1
         read (grp%lines, nml=integration, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, err)
         if (.not. more) exit
      end do
      call check(error, .not. allocated(err) .and. reads == 1 .and. n1 == 20 .and. n == 1.5_dp, &
                 'a group that reads is read once')
      if (allocated(error)) return
      call deck_from_string('&integration'//nl//'  n1 = 20'//nl//'  n = 1.5x'//nl//'  n1 = 3'//nl//'/'//nl, &
                            'bad.nml', deck)
      call find_group(deck, 'integration', grp, found, err)
      reads = 0
      do
         reads = reads + 1
         read (grp%lines, nml=integration, iostat=ios, iomsg=msg)
         call next_read(deck, grp, ios, msg, more, err)
         if (.not. more) exit
      end do
      call check(error, reads, 3, 'the whole group, then assignments 1 and 2')
      if (allocated(error)) return
      call check(error, allocated(err), 'an error')
      if (allocated(error)) return
      call check(error, index(err%message, "bad.nml, group &integration, line 3: variable 'n' has a bad value '1.5x' (") &
                 == 1, err%message)
   end subroutine test_next_read

   subroutine test_load_missing(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(fd_error_type), allocatable :: err

      call load_deck('no_such_deck_for_the_unit_tests.nml', deck, err)
      call check(error, allocated(err), 'a missing deck is an error')
      if (allocated(error)) return
      call check(error, err%message, "deck: file 'no_such_deck_for_the_unit_tests.nml' does not exist")
   end subroutine test_load_missing

   !> '$springs ... $end' is read as '&springs ... /'.
   subroutine test_legacy(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found
      integer :: n_springs, ios
      namelist /springs/ n_springs

      call deck_from_string(sample, 'sample.nml', deck)
      call find_group(deck, 'springs', grp, found, err)
      call check(error, found .and. .not. allocated(err), '$springs found')
      if (allocated(error)) return
      call check(error, size(grp%items), 1)
      if (allocated(error)) return
      call check(error, grp%items(1)%s, 'n_springs = 0')
      if (allocated(error)) return
      call check(error, trim(grp%lines(1)), '&springs n_springs = 0  /', 'what the namelist reader gets')
      if (allocated(error)) return
      n_springs = -1
      read (grp%lines, nml=springs, iostat=ios)
      call check(error, ios == 0 .and. n_springs == 0, 'the legacy group read by the namelist reader')
   end subroutine test_legacy

   !> Assignments, '/', and '&name' not first on its line, outside groups: errors naming the line.
   subroutine test_outside(error)
      type(error_type), allocatable, intent(out) :: error

      call expect_error('! ok'//nl//'&model /'//nl//'  n_dof = 2'//nl, &
                        "t.nml, line 3: 'n_dof = 2': an assignment outside any group", error)
      if (allocated(error)) return
      call expect_error('&model /'//nl//'/'//nl, "t.nml, line 2: '/': a '/' outside any group", error)
      if (allocated(error)) return
      call expect_error('&model /'//nl//'x&friction n_devices = 0 /'//nl, &
                        "t.nml, line 2: 'x&friction n_devices = 0 /': '&' not read as the start of a group", error)
      if (allocated(error)) return
      call expect_error(achar(194)//achar(160)//'&friction n_devices = 0 /'//nl, &
                        "(here a non-ASCII character, byte 194, comes before it)", error)
      if (allocated(error)) return
      call expect_error('Title of the deck'//nl//'&model /'//nl, "t.nml, line 1: 'Title of the deck': text outside", error)
      if (allocated(error)) return
      call expect_error('&model n_dof = 2 / mass = 1.0'//nl, &
                        "t.nml, line 1: 'mass = 1.0' after the end of group &model", error)
      if (allocated(error)) return
      call expect_error("&output dir = out/x /"//nl, "t.nml, line 1: 'x /' after the end of group &output", error)
      if (allocated(error)) return
      call expect_error('&model /'//nl//'&end'//nl, "t.nml, line 2: '&end' outside any group", error)
   end subroutine test_outside

   !> '& friction' (a blank after '&'), '&model=', and '&' in a group outside quotes.
   subroutine test_ampersand(error)
      type(error_type), allocatable, intent(out) :: error

      call expect_error('& friction'//nl//'/'//nl, "t.nml, line 1: '& friction': '&' must be followed by the group name", &
                        error)
      if (allocated(error)) return
      call expect_error('$ friction'//nl//'$end'//nl, "'$' must be followed by the group name", error)
      if (allocated(error)) return
      call expect_error('&model=2 /'//nl, "'&model=2 /' does not open a group", error)
      if (allocated(error)) return
      call expect_error('&model n_dof = 2 &x /'//nl, "t.nml, line 1, group &model: '&x /': '&' inside a group", error)
      if (allocated(error)) return
      call expect_error('&model'//nl//'  n_dof = 2'//nl//'&springs'//nl//'/'//nl, &
                        "t.nml, group &model (line 1): not closed by '/' before line 3 ('&springs')", error)
   end subroutine test_ampersand

   !> A NUL character is an error, in a deck given as text as in a file.
   subroutine test_nul(error)
      type(error_type), allocatable, intent(out) :: error

      call expect_error('&model'//nl//'  n_dof = 2'//achar(0)//'3'//nl//'/'//nl, &
                        "t.nml, line 2: a NUL character (byte 0) in the deck", error)
   end subroutine test_nul

   !> The same variable (or array element) twice in a group.
   subroutine test_twice(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found

      call deck_from_string('&damping'//nl//'  xi = 0.015'//nl//'  XI= 0.05'//nl//'/'//nl, 't.nml', deck)
      call find_group(deck, 'damping', grp, found, err)
      call check(error, allocated(err), 'xi given twice')
      if (allocated(error)) return
      call check(error, err%message, "t.nml, group &damping, line 3: 'xi' is assigned again (first at line 2); "// &
                 "give each variable once")
      if (allocated(error)) return
      call deck_from_string('&model mass(1) = 1.0, mass(2) = 2.0, mass( 1 ) = 3.0 /'//nl, 't.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call check(error, allocated(err), 'mass(1) given twice')
      if (allocated(error)) return
      call deck_from_string('&model mass(1) = 1.0, mass(2) = 2.0 /'//nl, 't.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call check(error, .not. allocated(err), 'two elements of an array')
   end subroutine test_twice

   !> The same element set by two assignments of different forms: a whole array (its first
   !> m elements, m counted as the namelist reader counts values), a section, an element with
   !> another spelling of its index, a substring. Parts that do not meet are not repeats.
   subroutine test_twice_forms(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: repeats(*) = [character(len=60) :: &
         'mass = 1.0, 2.0'//nl//'mass(2) = 3.0', &
         'mass(2) = 3.0'//nl//'mass = 1.0, 2.0', &
         'mass = 1.0 2.0'//nl//'mass(2) = 3.0', &
         'mass = 3*1.0'//nl//'mass(3) = 3.0', &
         'mass = , 2.0'//nl//'mass(2) = 3.0', &
         'mass(1:2) = 1.0, 2.0'//nl//'mass(02) = 3.0', &
         'mass(9:1:-2) = 5*1.0'//nl//'mass(5) = 3.0', &
         "label = 'a, b', 'c'"//nl//"label(2) = 'x'", &
         "label(1)(1:2) = 'ab'"//nl//"label(1) = 'x'", &
         "label(1)(1:2) = 'ab'"//nl//"label(1)(2:3) = 'x'"]
      character(len=*), parameter :: apart(*) = [character(len=60) :: &
         'mass = 1.0, 2.0'//nl//'mass(3) = 3.0', &
         'mass = 2*1.0'//nl//'mass(3) = 3.0', &
         "label = 'a, b', 'c'"//nl//"label(3) = 'x'", &
         'mass(1:9:2) = 5*1.0'//nl//'mass(2:10:2) = 5*3.0', &
         'mu_table_v(:, 1) = 1.0, 2.0'//nl//'mu_table_v(:, 2) = 1.0', &
         "label(1)(1:2) = 'ab'"//nl//"label(1)(3:4) = 'x'"]
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      character(len=:), allocatable :: text
      logical :: found
      integer :: k

      do k = 1, size(repeats)
         call deck_from_string('&model'//nl//trim(repeats(k))//nl//'/'//nl, 't.nml', deck)
         call find_group(deck, 'model', grp, found, err)
         call check(error, allocated(err), 'a repeat: '//trim(repeats(k)))
         if (allocated(error)) return
         call check(error, index(err%message, 't.nml, group &model, line 3: ') == 1 .and. &
                    index(err%message, 'at line 2; give each variable or element once') > 0, err%message)
         if (allocated(error)) return
      end do
      call deck_from_string('&model'//nl//'mass = 1.0, 2.0'//nl//'mass(2) = 3.0'//nl//'/'//nl, 't.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call check(error, err%message, "t.nml, group &model, line 3: 'mass(2)' sets again what 'mass' set at "// &
                 "line 2; give each variable or element once")
      if (allocated(error)) return
      do k = 1, size(apart)
         call deck_from_string('&model'//nl//trim(apart(k))//nl//'/'//nl, 't.nml', deck)
         call find_group(deck, 'model', grp, found, err)
         call check(error, .not. allocated(err), 'not a repeat: '//trim(apart(k)))
         if (allocated(error)) return
      end do
      ! 2100 elements one by one (beyond the pairwise comparison: neighbours in deck order),
      ! the last given again at once
      text = '&model'//nl
      do k = 1, 2100
         text = text//'mass('//trim(fmt_k(k))//') = 1.0'//nl
      end do
      call deck_from_string(text//'mass(2100) = 2.0'//nl//'/'//nl, 't.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call check(error, allocated(err), 'a repeat in a run of 2101 assignments')
      if (allocated(error)) return
      call check(error, index(err%message, "line 2102: 'mass(2100)' is assigned again") > 0, err%message)
   contains
      function fmt_k(i) result(t)
         integer, intent(in) :: i
         character(len=12) :: t
         write (t, '(i0)') i
      end function fmt_k
   end subroutine test_twice_forms

   !> gfortran's namelist reader takes a separator followed by a comment and the end of the
   !> line for a null value; the group's lines reach it without their comments, so the
   !> values read are those the deck writes (the standard: a comment is ignored).
   subroutine test_comment_no_value(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found
      integer :: ios
      real(dp) :: u0(3), v0(2)
      namelist /model/ u0, v0

      u0 = -1.0_dp; v0 = -1.0_dp
      call deck_from_string('&model'//nl//'  u0 = 0.01,   ! first storey'//nl//'       0.02   ! second'//nl// &
                            '  v0 = ! m/s'//nl//'  0.5'//nl//'/'//nl, 't.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call check(error, found .and. .not. allocated(err), 'found')
      if (allocated(error)) return
      read (grp%lines, nml=model, iostat=ios)
      call check(error, ios, 0, 'read')
      if (allocated(error)) return
      call check(error, all(u0 == [0.01_dp, 0.02_dp, -1.0_dp]), 'u0 = 0.01, 0.02, (unchanged)')
      if (allocated(error)) return
      call check(error, all(v0 == [0.5_dp, -1.0_dp]), 'v0 = 0.5, (unchanged)')
   end subroutine test_comment_no_value

   !> A text continued on the next line: an error naming the line, not the reader's padded
   !> records' reading of it.
   subroutine test_open_text(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found

      call deck_from_string("&model"//nl//"  label = 'upper"//nl//"  block', 'lower'"//nl//"/"//nl, 't.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call check(error, allocated(err), 'an error')
      if (allocated(error)) return
      call check(error, err%message, "t.nml, line 2, group &model: a text ('...) is not closed on its line; "// &
                 "close each text on the line where it starts")
      if (allocated(error)) return
      call deck_from_string("&model"//nl//"  label = 'it''s ! not a comment', ""a 'b'"" ! one"//nl//"/"//nl, &
                            't.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call check(error, .not. allocated(err), 'texts closed on their line')
   end subroutine test_open_text

   !> A byte order mark (EF BB BF, written by some Windows editors) before '&model' is no
   !> text outside a group; the same bytes elsewhere are (a non-breaking space's family).
   subroutine test_bom(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: bom = achar(239)//achar(187)//achar(191)
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found

      call deck_from_string(bom//'&model n_dof = 1 /'//nl, 't.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call check(error, found .and. .not. allocated(err), 'the group after the mark is found')
      if (allocated(error)) return
      call deck_from_string('! x'//nl//bom//'&model n_dof = 1 /'//nl, 't.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call check(error, allocated(err), 'the bytes on another line are text outside a group')
   end subroutine test_bom

   !> longest_string: quoted strings of a variable and its elements, a doubled quote counted
   !> once, other variables ignored; the line of the longest.
   subroutine test_longest(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found
      integer :: length, line

      call deck_from_string("&friction"//nl//"  law = 'velocity', ""hysteretic"""//nl// &
                            "  law(3) = 'it''s   x', name = '"//repeat('n', 50)//"'"//nl//"/"//nl, 't.nml', deck)
      call find_group(deck, 'friction', grp, found, err)
      call check(error, found .and. .not. allocated(err), 'found')
      if (allocated(error)) return
      call longest_string(grp, 'law', length, line)
      call check(error, length == 10 .and. line == 2, "law: 'hysteretic', line 2")
      if (allocated(error)) return
      call longest_string(grp, 'name', length, line)
      call check(error, length == 50 .and. line == 3, 'name: 50 characters, line 3')
      if (allocated(error)) return
      call longest_string(grp, 'dir', length, line)
      call check(error, length == 0 .and. line == 0, 'dir: not given')
      if (allocated(error)) return
      call deck_from_string("&friction law(3) = 'it''s    x' /"//nl, 't.nml', deck)
      call find_group(deck, 'friction', grp, found, err)
      call longest_string(grp, 'law', length, line)
      call check(error, length, 9, "it's    x: a doubled quote is one character")
   end subroutine test_longest

   !> given_elements against gfortran's own reader: each group is read twice, its arrays set
   !> to two different values first; an element the read left at both is not given. Every
   !> form the reader takes: lists, an element and the values after it, sections with strides
   !> (negative too), null values (empty places, 'r*'), repeat counts, 2-D arrays.
   subroutine test_given(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=40), parameter :: cases(*) = [character(len=40) :: &
         'a = 1, 2', 'a = 1 2 3', 'a(2) = 1, 2, 3', 'a(2:5) = 1', 'a = , 2', 'a = 2*, 3', &
         'a = 1 2*, 4', 'a = 1,,3', 'a = 1, 2,', 'a(2:6:2) = 7, 8', 'a(5:2:-1) = 7, 8', &
         'a(1:6:2) = 1, 2, 3', 'a(:3) = 9', 'a(4:) = 1 2 3', 'a(6:1:-2) = , 5', 'a = 3*1.0, 2*, 5', &
         'a(1) = 1, a(3) = 3', 'a = 1.0 , , 4', 'A(2) = 5', &
         'b(2,:) = 7, 8', 'b(:,2) = 7, 8, 9', 'b = 7, 8, 9, 10', 'b(2,2) = 7, 8, 9', &
         'b(:, 3) = 1 2', 'b(2, :) = , 4', 'b = 4*0.5', 'b(3:1:-1, 2) = 1, , 3', 'a = 1, b(1,1) = 2', &
         'b(2:3, 2:3) = 1, 2, 3, 4', 'b(1, 2:3) = 1*, 5']
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      real(dp) :: a(6), b(3, 3), a1(6), b1(3, 3)
      logical :: found, ga(6), gb(9)
      integer :: i, ios
      namelist /g/ a, b

      do i = 1, size(cases)
         call deck_from_string('&g'//nl//'  '//trim(cases(i))//nl//'/'//nl, 't.nml', deck)
         call find_group(deck, 'g', grp, found, err)
         call check(error, found .and. .not. allocated(err), trim(cases(i))//': found')
         if (allocated(error)) return
         a = -7777.0_dp; b = -7777.0_dp
         read (grp%lines, nml=g, iostat=ios)
         ! values after an element alone ('a(2) = 1, 2, 3') are gfortran's extension, refused
         ! under -std=f2008: nothing is then read
         if (ios /= 0 .and. (cases(i) == 'a(2) = 1, 2, 3' .or. cases(i) == 'b(2,2) = 7, 8, 9')) cycle
         call check(error, ios, 0, trim(cases(i))//': read')
         if (allocated(error)) return
         a1 = a; b1 = b
         a = -8888.0_dp; b = -8888.0_dp
         read (grp%lines, nml=g, iostat=ios)
         call given_elements(grp, 'a', [6], ga)
         call given_elements(grp, 'b', [3, 3], gb)
         call check(error, all(ga .eqv. .not. (a1 == -7777.0_dp .and. a == -8888.0_dp)), trim(cases(i))//': a')
         if (allocated(error)) return
         call check(error, all(gb .eqv. .not. reshape(b1 == -7777.0_dp .and. b == -8888.0_dp, [9])), &
                    trim(cases(i))//': b')
         if (allocated(error)) return
      end do
      ! a scalar, and a variable of the same prefix
      call deck_from_string('&g'//nl//'  ab = 1, a = 2'//nl//'/'//nl, 't.nml', deck)
      call find_group(deck, 'g', grp, found, err)
      call given_elements(grp, 'ab', [1], ga(1:1))
      call given_elements(grp, 'b', [1], ga(2:2))
      call check(error, ga(1) .and. .not. ga(2), "'ab' given, 'b' not")
   end subroutine test_given

   !> A value that is the largest (or most negative) number is given like any other.
   subroutine test_given_extremes(error)
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(group_text) :: grp
      type(fd_error_type), allocatable :: err
      logical :: found, gv(3), gn(1)

      call deck_from_string('&model'//nl//'  n_dof = -2147483647, v0 = 0.0, -1.7976931348623157e308'//nl// &
                            '/'//nl, 't.nml', deck)
      call find_group(deck, 'model', grp, found, err)
      call given_elements(grp, 'v0', [3], gv)
      call given_elements(grp, 'n_dof', [1], gn)
      call check(error, gn(1) .and. all(gv .eqv. [.true., .true., .false.]), 'n_dof and v0(1:2) given')
   end subroutine test_given_extremes

   !> check_groups on a deck gives an error containing `text`.
   subroutine expect_error(deck_string, text, error)
      character(len=*), intent(in) :: deck_string, text
      type(error_type), allocatable, intent(out) :: error
      type(deck_text) :: deck
      type(fd_error_type), allocatable :: err

      call deck_from_string(deck_string, 't.nml', deck)
      call check_groups(deck, [character(len=10) :: 'model', 'friction', 'output', 'springs', 'damping'], err)
      call check(error, allocated(err), 'an error expected: '//text)
      if (allocated(error)) return
      call check(error, index(err%message, text) > 0, err%message)
   end subroutine expect_error

end module test_fd_namelist
