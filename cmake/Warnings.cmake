# Project-wide warning flags as an INTERFACE target, so third-party code is untouched.
add_library(poundsim_warnings INTERFACE)
target_compile_options(poundsim_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast -Wcast-align
  -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion -Wformat=2
  -Wimplicit-fallthrough -Wmisleading-indentation -Wduplicated-cond -Wlogical-op)
if(POUNDSIM_WARNINGS_AS_ERRORS)
  target_compile_options(poundsim_warnings INTERFACE -Werror)
endif()
