# Project-wide warning flags as an INTERFACE target, so third-party code is untouched.
# Not -Wnull-dereference: with GCC 12 at -O2 it fires inside Eigen's and CLI11's inlined headers
# on code that cannot dereference null.
add_library(poundsim_warnings INTERFACE)
target_compile_options(poundsim_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast -Wcast-align
  -Woverloaded-virtual -Wdouble-promotion -Wformat=2
  -Wimplicit-fallthrough -Wmisleading-indentation -Wduplicated-cond -Wlogical-op)
if(POUNDSIM_WARNINGS_AS_ERRORS)
  target_compile_options(poundsim_warnings INTERFACE -Werror)
endif()
