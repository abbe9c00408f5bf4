# CheckReadmeExample.cmake (cmake -P): the README's library example must be the code that
# examples/sky_view_factor.cpp compiles, the lines between its "// [readme]" and
# "// [/readme]" markers, so the README cannot show code that does not build.
#   cmake -DREADME=README.md -DEXAMPLE=examples/sky_view_factor.cpp -P CheckReadmeExample.cmake
file(READ ${EXAMPLE} example)
string(REGEX MATCH "// \\[readme\\]\n(.*)\n// \\[/readme\\]" found "${example}")
if(NOT found)
  message(FATAL_ERROR "${EXAMPLE}: no // [readme] ... // [/readme] region")
endif()
set(region "${CMAKE_MATCH_1}")
file(READ ${README} readme)
string(FIND "${readme}" "```cpp\n${region}\n```" at)
if(at EQUAL -1)
  message(FATAL_ERROR "README.md's library example differs from ${EXAMPLE}'s [readme] region; "
                      "README.md must show exactly:\n```cpp\n${region}\n```")
endif()
