# cmake -DPHIQ=phiq -DHELP2MAN=help2man -DVERSION=0.1.0 -DOUT=phiq.1 -P man_page.cmake: the man page phiq(1), help2man's rendering of
# `phiq --help`, with a COMMANDS section holding each command's own --help (help2man reads only the top level).
set(commands run check assemble batch compare generate convert plot sweep-accuracy)
get_filename_component(dir ${OUT} DIRECTORY)
set(include_file ${dir}/phiq_man_commands.h2m)
set(text "[COMMANDS]\n")
foreach(c IN LISTS commands)
  execute_process(COMMAND ${PHIQ} ${c} --help OUTPUT_VARIABLE help RESULT_VARIABLE status)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${PHIQ} ${c} --help failed (${status})")
  endif()
  # the usage line names the binary by the path it was run from: the page names it phiq
  string(REPLACE "${PHIQ}" "phiq" help "${help}")
  # roff: a line starting with '.' or '\'' would be a request; a backslash an escape
  string(REPLACE "\\" "\\e" help "${help}")
  string(REGEX REPLACE "\n([.'])" "\n\\\\&\\1" help "${help}")
  string(APPEND text ".SS \"phiq ${c}\"\n.nf\n${help}.fi\n")
endforeach()
string(APPEND text "[SEE ALSO]\nThe full documentation of every command, option, exit status and file format is tools/README.md of the
phiq sources; the scene format is models/README.md.\n")
file(WRITE ${include_file} "${text}")
execute_process(COMMAND ${HELP2MAN} --no-info --no-discard-stderr --version-string=${VERSION}
                        --name "sparse, large-scale multibody kinematics"
                        --include ${include_file} --output ${OUT} ${PHIQ}
                RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "help2man failed (${status})")
endif()
