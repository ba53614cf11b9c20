# A manual page for one of the bench tools, made from the program's own
# --help (and, for tase, `tase help COMMAND` of every command it lists), so
# that the page says what the program says. Run at build time:
#   cmake -DPROG=path/to/tase -DNAME=tase -DSUMMARY="..." -DVERSION=0.3.0
#         -DOUT=tase.1 [-DDOCDIR=/usr/share/doc/tase-tools] -P tase-manpage.cmake
# writes OUT (roff); tools/CMakeLists.txt compresses it with
# tase-gzip.cmake, as Debian installs manual pages. The full manual is docs/TOOLS.md (the tase-tools package
# installs it in /usr/share/doc/tase-tools/).
if(NOT DEFINED DOCDIR)
  set(DOCDIR /usr/share/doc/tase-tools)
endif()
foreach(v PROG NAME SUMMARY VERSION OUT)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "tase-manpage.cmake: -D${v}= is missing")
  endif()
endforeach()

# Text as roff that prints it as it is: a backslash is \e, a hyphen \- (an
# option's, not a typographic hyphen), a line that would start a request (a
# dot or an apostrophe first) is protected with \&.
function(tase_roff_text text out)
  string(REPLACE "\\" "\\e" text "${text}")
  string(REPLACE "-" "\\-" text "${text}")
  string(REGEX REPLACE "(^|\n)([.'])" "\\1\\\\&\\2" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

function(tase_help out)
  execute_process(COMMAND ${PROG} ${ARGN} OUTPUT_VARIABLE text ERROR_VARIABLE err
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0 OR text STREQUAL "")
    message(FATAL_ERROR "tase-manpage.cmake: '${PROG} ${ARGN}' failed (${rc}): ${err}")
  endif()
  string(REGEX REPLACE "\n+$" "" text "${text}")
  tase_roff_text("${text}" text)
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

string(TOUPPER "${NAME}" upper)
tase_roff_text("${DOCDIR}/TOOLS.md" manual)
string(TIMESTAMP date "%Y-%m-%d" UTC)
tase_help(usage --help)
set(page ".TH ${upper} 1 \"${date}\" \"${NAME} ${VERSION}\" \"TASE gimbal bench tools\"
.SH NAME
${NAME} \\- ${SUMMARY}
.SH DESCRIPTION
This page is the program's own help (\\fB${NAME} \\-\\-help\\fR).
The full manual, with examples, is
\\fI${manual}\\fR (docs/TOOLS.md in the source).
.PP
.nf
${usage}
.fi
")

# tase: every command of the list in its --help ("  NAME  what it does"
# between "commands:" and the next unindented line), with its own help.
if(usage MATCHES "\ncommands:\n")
  string(REGEX REPLACE ".*\ncommands:\n" "" list "${usage}")
  string(REGEX REPLACE "\n[^ ].*" "" list "${list}")
  string(REPLACE ";" "," list "${list}")
  string(REPLACE "\n" ";" lines "${list}")
  string(APPEND page ".SH COMMANDS\n")
  # (the list is roff already: a hyphen in a name, gyro-zero's, is \-)
  foreach(line IN LISTS lines)
    if(line MATCHES "^  ([a-z]([a-z]|\\\\-)*) ")
      set(title ${CMAKE_MATCH_1})
      string(REPLACE "\\-" "-" c "${title}")
      tase_help(text help ${c})
      # the exit status is the same for every command: said once, above
      string(REGEX REPLACE "\nexit status:.*" "" text "${text}")
      string(APPEND page ".SS ${title}\n.nf\n${text}\n.fi\n")
    endif()
  endforeach()
endif()
string(APPEND page ".SH SEE ALSO
\\fBtase\\fR(1), \\fBtase\\-sim\\fR(1);
\\fI${manual}\\fR
")

file(WRITE "${OUT}" "${page}")
