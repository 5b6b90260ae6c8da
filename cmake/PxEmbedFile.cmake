# cmake -DINPUT=x.cl -DOUTPUT=x.c -DNAME=x -DINCLUDE_DIRS=dir -P PxEmbedFile.cmake
# Inlines #include "..." lines (searched next to the including file, then in
# INCLUDE_DIRS), then writes the text as a NUL-terminated byte array.
# #line directives keep the original file names (relative to INCLUDE_DIRS)
# and line numbers, so OpenCL build logs point at the real source lines.
cmake_minimum_required(VERSION 3.25)
# Works on the text as one string (never as a CMake list: C code has ';').

# The name of `path` in #line directives: relative to an include dir.
function(px_line_name path out_var)
  set(name "${path}")
  foreach(d IN ITEMS ${INCLUDE_DIRS})
    file(RELATIVE_PATH rel "${d}" "${path}")
    if(NOT rel MATCHES "^\\.\\.")
      set(name "${rel}")
      break()
    endif()
  endforeach()
  set(${out_var} "${name}" PARENT_SCOPE)
endfunction()

function(px_inline_includes path depth out_var)
  if(depth GREATER 16)
    message(FATAL_ERROR "include nesting too deep at ${path}")
  endif()
  file(READ ${path} text)
  get_filename_component(dir ${path} DIRECTORY)
  px_line_name(${path} name)
  set(result "#line 1 \"${name}\"\n")
  set(line 1) # line number of the first character of `text`
  while(TRUE)
    string(REGEX MATCH "#[ \t]*include[ \t]*\"([^\"]+)\"" m "${text}")
    if(m STREQUAL "")
      break()
    endif()
    set(inc "${CMAKE_MATCH_1}")
    string(FIND "${text}" "${m}" pos)
    string(SUBSTRING "${text}" 0 ${pos} before)
    string(REGEX MATCHALL "\n" newlines "${before}")
    list(LENGTH newlines count)
    math(EXPR line "${line} + ${count}")
    string(LENGTH "${m}" mlen)
    math(EXPR after_pos "${pos} + ${mlen}")
    string(SUBSTRING "${text}" ${after_pos} -1 text)
    set(found "")
    foreach(d IN ITEMS ${dir} ${INCLUDE_DIRS})
      if(EXISTS "${d}/${inc}" AND found STREQUAL "")
        set(found "${d}/${inc}")
      endif()
    endforeach()
    if(found STREQUAL "")
      message(FATAL_ERROR "${path}: cannot find included file \"${inc}\"")
    endif()
    math(EXPR d1 "${depth} + 1")
    px_inline_includes(${found} ${d1} body)
    # The rest of `text` starts with the newline of the #include line, which
    # ends the #line directive: the next line is numbered line + 1.
    math(EXPR next "${line} + 1")
    string(APPEND result "${before}/* begin ${inc} */\n${body}\n/* end ${inc} */\n"
           "#line ${next} \"${name}\"")
  endwhile()
  string(APPEND result "${text}")
  set(${out_var} "${result}" PARENT_SCOPE)
endfunction()

px_inline_includes(${INPUT} 0 source)
set(tmp "${OUTPUT}.txt")
file(WRITE ${tmp} "${source}")
file(READ ${tmp} hex HEX)
file(REMOVE ${tmp})
string(LENGTH "${hex}" hexlen)
math(EXPR nbytes "${hexlen} / 2")
# Character constants ('\xc3'), not 0xc3: bytes >= 0x80 (UTF-8 in comments)
# must not overflow a signed char.
string(REGEX REPLACE "([0-9a-f][0-9a-f])" "'\\\\x\\1'," bytes "${hex}")
# 16 bytes per line (CMake regexes have no {n} repetition).
string(REPEAT "'[^']+'," 16 sixteen)
string(REGEX REPLACE "(${sixteen})" "\\1\n" bytes "${bytes}")
file(WRITE ${OUTPUT}
"/* Generated from ${INPUT} by PxEmbedFile.cmake; do not edit. */
#include <stddef.h>
extern const char px_cl_source_${NAME}[];
extern const size_t px_cl_source_${NAME}_size;
const char px_cl_source_${NAME}[] = {
${bytes}'\\0'};
/* Length without the terminating NUL. */
const size_t px_cl_source_${NAME}_size = ${nbytes};
")
