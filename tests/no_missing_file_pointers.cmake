# Fails when a file of the repository points at notes that ship only beside it, not in it: the
# design notes, the platform notes, the shared folder, the paper sources. A user who clones
# patchcull has none of them, so repository text states the fact itself or cites the paper by
# title and authors (README, "Papers").
#   cmake -DSOURCE_DIR=<repository root> -P no_missing_file_pointers.cmake
# Checks the files git tracks (every file under SOURCE_DIR, build trees aside, when it is not a
# git checkout) and prints each offending file:line. The patterns are written with character
# classes so that this script does not match itself.
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED SOURCE_DIR)
  message(FATAL_ERROR "usage: cmake -DSOURCE_DIR=<repository root> -P no_missing_file_pointers.cmake")
endif()
set(pattern "shar[e]d/|DESIG[N]\\.md|PLATFOR[M]\\.md|seed[s]/")

find_program(GIT_EXECUTABLE git)
if(GIT_EXECUTABLE AND EXISTS "${SOURCE_DIR}/.git")
  execute_process(COMMAND "${GIT_EXECUTABLE}" -c core.quotePath=false ls-files
                  WORKING_DIRECTORY "${SOURCE_DIR}" OUTPUT_VARIABLE listed RESULT_VARIABLE status)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "git ls-files failed in ${SOURCE_DIR}")
  endif()
  string(STRIP "${listed}" listed)
  string(REPLACE ";" "\\;" listed "${listed}")
  string(REPLACE "\n" ";" files "${listed}")
else()
  file(GLOB_RECURSE files RELATIVE "${SOURCE_DIR}" "${SOURCE_DIR}/*")
  list(FILTER files EXCLUDE REGEX "^(build[^/]*|\\.git)/")
endif()
list(LENGTH files count)
if(count EQUAL 0)
  message(FATAL_ERROR "no files found under ${SOURCE_DIR}")
endif()

set(found "")
foreach(relative IN LISTS files)
  set(path "${SOURCE_DIR}/${relative}")
  if(NOT EXISTS "${path}" OR IS_DIRECTORY "${path}")
    continue()  # deleted in the work tree, or a submodule
  endif()
  # Fast filter first; line numbers only for the files that match.
  file(STRINGS "${path}" hits REGEX "${pattern}")
  if(NOT hits)
    continue()
  endif()
  # One list element per line: semicolons and brackets (list syntax to CMake) masked first.
  file(READ "${path}" content)
  string(REPLACE ";" "<semicolon>" content "${content}")
  string(REPLACE "[" "<open>" content "${content}")
  string(REPLACE "]" "<close>" content "${content}")
  string(REPLACE "\n" ";" lines "${content}")
  set(number 0)
  foreach(line IN LISTS lines)
    math(EXPR number "${number} + 1")
    if(line MATCHES "${pattern}")
      string(APPEND found "${relative}:${number}: '${CMAKE_MATCH_0}'\n")
    endif()
  endforeach()
endforeach()
if(found)
  message(FATAL_ERROR "text points at files the repository does not have (state the fact, or cite "
                      "the paper by title and authors):\n${found}")
endif()
message("${count} files checked: no pointers at files outside the repository")
