!> Generic support for namelist decks: a deck held in memory as lines, the text of one
!> group found in it, and messages that name the file, group, line, variable and value.
!> The group readers in fd_deck do the namelist reads themselves (a namelist can only be
!> read where it is declared); on failure they re-read the group one assignment at a
!> time with group_item to find the variable and value at fault.
module fd_namelist
   use fd_error, only: error_type, fatal_error, fmt_int
   use fd_textio, only: line_type, read_text_file, split_lines, lower
   implicit none
   private

   public :: deck_text, group_text, load_deck, deck_from_string, find_group, group_item, group_read_error
   public :: check_groups, group_opened

   !> A whole deck in memory.
   type :: deck_text
      character(len=:), allocatable :: path          !! the deck file
      type(line_type), allocatable :: lines(:)       !! its lines
   end type deck_text

   !> One group of a deck, ready for an internal namelist read.
   type :: group_text
      character(len=:), allocatable :: name          !! group name, lower case
      character(len=:), allocatable :: lines(:)      !! its lines, from '&name' to '/'
      integer :: first_line = 0                      !! deck line of '&name'
      type(line_type), allocatable :: items(:)       !! the assignments 'var = value'
      integer, allocatable :: item_line(:)           !! deck line of each assignment
   end type group_text

contains

   !> Read a deck file into memory.
   subroutine load_deck(path, deck, error)
      character(len=*), intent(in) :: path                !! deck file
      type(deck_text), intent(out) :: deck                !! its text
      type(error_type), allocatable, intent(out) :: error !! missing or unreadable file

      deck%path = path
      call read_text_file(path, deck%lines, error)
      if (allocated(error)) error%message = "deck: "//error%message
   end subroutine load_deck

   !> A deck given as text (lines separated by newlines); path names it in messages and
   !> is the base of relative record paths.
   pure subroutine deck_from_string(text, path, deck)
      character(len=*), intent(in) :: text   !! the deck
      character(len=*), intent(in) :: path   !! name used for the deck
      type(deck_text), intent(out) :: deck   !! its text as lines

      deck%path = path
      call split_lines(text, deck%lines)
   end subroutine deck_from_string

   !> The first word of a line, lower case, if it opens a group ('&name'); blank if not.
   pure function group_opened(line) result(name)
      character(len=*), intent(in) :: line !! a deck line
      character(len=64) :: name            !! the group it opens, lower case; blank if none
      integer :: e, b

      name = ''
      b = verify(line, ' '//achar(9))
      if (b == 0) return
      if (line(b:b) /= '&' .or. b == len(line)) return
      e = scan(line(b + 1:), ' ,/'//achar(9))
      if (e == 0) then
         name = lower(line(b + 1:))
      else
         name = lower(line(b + 1:b + e - 1))
      end if
      if (name == 'end') name = ''
   end function group_opened

   !> Every group of the deck must be one of the known names, and appear once.
   subroutine check_groups(deck, known, error)
      type(deck_text), intent(in) :: deck                 !! the deck
      character(len=*), intent(in) :: known(:)            !! names of the known groups
      type(error_type), allocatable, intent(out) :: error !! unknown or repeated group
      character(len=64) :: name
      integer :: i, j, count(size(known))

      count = 0
      do i = 1, size(deck%lines)
         name = group_opened(deck%lines(i)%s)
         if (len_trim(name) == 0) cycle
         do j = 1, size(known)
            if (name == trim(known(j))) exit
         end do
         if (j > size(known)) then
            call fatal_error(error, deck%path//", line "//trim(fmt_int(i))//": unknown group &"//trim(name)// &
                             "; the groups are "//trim(join(known)))
            return
         end if
         count(j) = count(j) + 1
         if (count(j) > 1) then
            call fatal_error(error, deck%path//", line "//trim(fmt_int(i))//": group &"//trim(name)// &
                             " appears more than once")
            return
         end if
      end do
   contains
      function join(words) result(str)
         character(len=*), intent(in) :: words(:)
         character(len=512) :: str
         integer :: k
         str = ''
         do k = 1, size(words)
            str = trim(str)//' &'//trim(words(k))
            if (k < size(words)) str = trim(str)//','
         end do
         str = adjustl(str)
      end function join
   end subroutine check_groups

   !> Find a group in the deck and split it into assignments.
   subroutine find_group(deck, name, grp, found, error)
      type(deck_text), intent(in) :: deck                 !! the deck
      character(len=*), intent(in) :: name                !! group name, lower case
      type(group_text), intent(out) :: grp                !! the group's text
      logical, intent(out) :: found                       !! the group is present
      type(error_type), allocatable, intent(out) :: error !! group not closed by '/'
      integer :: i, first, last, width, n, cap
      character(len=:), allocatable :: body
      integer, allocatable :: line_of(:)
      logical :: closed

      grp%name = name
      found = .false.
      first = 0
      do i = 1, size(deck%lines)
         if (group_opened(deck%lines(i)%s) == name) then
            first = i
            exit
         end if
      end do
      if (first == 0) return
      found = .true.
      grp%first_line = first
      ! body: the text after '&name' up to the closing '/', comments removed, in buffers
      ! large enough for the rest of the deck (n characters used)
      cap = 0
      do i = first, size(deck%lines)
         cap = cap + len(deck%lines(i)%s) + 1
      end do
      allocate (character(len=cap) :: body)
      allocate (line_of(cap))
      n = 0
      closed = .false.
      last = first
      do i = first, size(deck%lines)
         if (i > first .and. len_trim(group_opened(deck%lines(i)%s)) > 0) exit
         last = i
         call append_line(deck%lines(i)%s, i == first, body, line_of, n, i, closed)
         if (closed) exit
      end do
      if (.not. closed) then
         call fatal_error(error, deck%path//", group &"//name//" (line "//trim(fmt_int(first))// &
                          "): not closed by '/'")
         return
      end if
      width = 1
      do i = first, last
         width = max(width, len(deck%lines(i)%s))
      end do
      allocate (character(len=width) :: grp%lines(last - first + 1))
      do i = first, last
         grp%lines(i - first + 1) = deck%lines(i)%s
      end do
      call split_items(body(1:n), line_of(1:n), grp%items, grp%item_line)
   end subroutine find_group

   !> Append one deck line to the body of a group, without comments, stopping at '/'.
   pure subroutine append_line(line, is_first, body, line_of, n, lineno, closed)
      character(len=*), intent(in) :: line
      logical, intent(in) :: is_first
      character(len=*), intent(inout) :: body       !! buffer, body(1:n) used
      integer, intent(inout) :: line_of(:)          !! deck line of each character
      integer, intent(inout) :: n                   !! characters used
      integer, intent(in) :: lineno
      logical, intent(out) :: closed
      integer :: i, start
      character(len=1) :: quote

      closed = .false.
      start = 1
      if (is_first) then
         start = index(line, '&') + 1
         do while (start <= len(line))
            if (scan(line(start:start), ' ,'//achar(9)) > 0) exit
            start = start + 1
         end do
      end if
      quote = ' '
      do i = start, len(line)
         if (quote /= ' ') then
            if (line(i:i) == quote) quote = ' '
         else if (line(i:i) == '"' .or. line(i:i) == "'") then
            quote = line(i:i)
         else if (line(i:i) == '!') then
            exit
         else if (line(i:i) == '/') then
            closed = .true.
            exit
         else if (line(i:i) == '&') then
            if (lower(line(i:min(i + 3, len(line)))) == '&end') then
               closed = .true.
               exit
            end if
         end if
         n = n + 1
         body(n:n) = line(i:i)
         line_of(n) = lineno
      end do
      n = n + 1
      body(n:n) = ' '
      line_of(n) = lineno
   end subroutine append_line

   !> Split a group body at the start of each 'name =' or 'name(index) ='.
   pure subroutine split_items(body, line_of, items, item_line)
      character(len=*), intent(in) :: body
      integer, intent(in) :: line_of(:)
      type(line_type), allocatable, intent(out) :: items(:)
      integer, allocatable, intent(out) :: item_line(:)
      integer, allocatable :: starts(:)
      integer :: i, j, depth
      character(len=1) :: quote

      allocate (starts(0))
      quote = ' '
      do i = 1, len(body)
         if (quote /= ' ') then
            if (body(i:i) == quote) quote = ' '
            cycle
         end if
         if (body(i:i) == '"' .or. body(i:i) == "'") then
            quote = body(i:i)
            cycle
         end if
         if (body(i:i) /= '=') cycle
         ! walk back over blanks, an index in parentheses, and the name
         j = i - 1
         do while (j >= 1)
            if (body(j:j) /= ' ') exit
            j = j - 1
         end do
         if (j >= 1) then
            if (body(j:j) == ')') then
               depth = 0
               do while (j >= 1)
                  if (body(j:j) == ')') depth = depth + 1
                  if (body(j:j) == '(') depth = depth - 1
                  j = j - 1
                  if (depth == 0) exit
               end do
            end if
         end if
         do while (j >= 1)
            if (.not. is_name_char(body(j:j))) exit
            j = j - 1
         end do
         starts = [starts, j + 1]
      end do
      allocate (items(size(starts)), item_line(size(starts)))
      do i = 1, size(starts)
         if (i < size(starts)) then
            items(i)%s = trim(adjustl(body(starts(i):starts(i + 1) - 1)))
         else
            items(i)%s = trim(adjustl(body(starts(i):)))
         end if
         ! drop a trailing separator comma
         j = len(items(i)%s)
         if (j > 0) then
            if (items(i)%s(j:j) == ',') items(i)%s = trim(items(i)%s(1:j - 1))
         end if
         item_line(i) = line_of(min(starts(i), size(line_of)))
      end do
   contains
      pure logical function is_name_char(c)
         character(len=1), intent(in) :: c
         is_name_char = (c >= 'a' .and. c <= 'z') .or. (c >= 'A' .and. c <= 'Z') .or. &
                        (c >= '0' .and. c <= '9') .or. c == '_' .or. c == '%'
      end function is_name_char
   end subroutine split_items

   !> One assignment of a group as a namelist record of its own: '&name item /'.
   pure subroutine group_item(grp, i, record)
      type(group_text), intent(in) :: grp                  !! the group
      integer, intent(in) :: i                             !! index of the assignment
      character(len=:), allocatable, intent(out) :: record !! namelist text to read

      record = '&'//grp%name//' '//grp%items(i)%s//' /'
   end subroutine group_item

   !> Error for a group that could not be read: names the assignment at fault when the
   !> one-by-one re-read found it (bad >= 1), else reports the reader's message.
   subroutine group_read_error(deck, grp, bad, msg, error)
      type(deck_text), intent(in) :: deck                 !! the deck
      type(group_text), intent(in) :: grp                 !! the group
      integer, intent(in) :: bad                          !! failing assignment, 0 if none found
      character(len=*), intent(in) :: msg                 !! the namelist reader's message
      type(error_type), allocatable, intent(out) :: error !! the error
      character(len=:), allocatable :: item, var, val
      integer :: eq

      if (bad < 1 .or. bad > size(grp%items)) then
         call fatal_error(error, deck%path//", group &"//grp%name//" (line "//trim(fmt_int(grp%first_line))// &
                          "): cannot be read: "//trim(msg))
         return
      end if
      item = grp%items(bad)%s
      eq = index(item, '=')
      var = trim(adjustl(item(1:max(eq - 1, 0))))
      val = trim(adjustl(item(eq + 1:)))
      if (index(msg, 'Cannot match namelist object name '//lower(var)) > 0 .or. &
          index(msg, 'Cannot match namelist object name '//var) > 0) then
         call fatal_error(error, deck%path//", group &"//grp%name//", line "//trim(fmt_int(grp%item_line(bad)))// &
                          ": unknown variable '"//var//"' (value "//val//")")
      else
         call fatal_error(error, deck%path//", group &"//grp%name//", line "//trim(fmt_int(grp%item_line(bad)))// &
                          ": variable '"//var//"' has a bad value '"//val//"' ("//trim(msg)//")")
      end if
   end subroutine group_read_error

end module fd_namelist
