# ccache (PH_CCACHE, on by default), when it is installed (scripts/setup installs it): every compilation goes
# through it, in every preset. Paths under the source tree are hashed relative to it (base_dir) and the build
# folder is not hashed (hash_dir), so that a fresh clone elsewhere on the same machine (CI's) hits the cache
# that a developer's builds filled; the sloppiness is what ccache asks for with precompiled headers included by
# -include, as CMake does. The cache is ccache's own (~/.cache/ccache, CCACHE_DIR), shared by all presets.
option(PH_CCACHE "Compile through ccache when it is installed" ON)
find_program(PH_CCACHE_PROGRAM ccache)
if(PH_CCACHE AND PH_CCACHE_PROGRAM AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  set(CMAKE_CXX_COMPILER_LAUNCHER
      ${CMAKE_COMMAND} -E env CCACHE_BASEDIR=${PROJECT_SOURCE_DIR} CCACHE_NOHASHDIR=1
      CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime
      ${PH_CCACHE_PROGRAM})
endif()
