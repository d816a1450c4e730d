# SPDX-License-Identifier: Apache-2.0
# bench_bullet: surface mass-spring against a Bullet soft body at the same
# dent (issue 17). Built only when libbullet-dev (pkg-config bullet) and a
# C++ compiler are installed: Bullet is a benchmark peer, never a product
# dependency.
pkg_check_modules(BULLET QUIET IMPORTED_TARGET bullet)
include(CheckLanguage)
check_language(CXX)
if(BULLET_FOUND AND CMAKE_CXX_COMPILER)
  enable_language(CXX)
  add_executable(bench_bullet ${CMAKE_CURRENT_LIST_DIR}/bench_bullet.c ${CMAKE_CURRENT_LIST_DIR}/bullet_soft.cpp)
  target_link_libraries(bench_bullet PRIVATE viscera_sim viscera_test_support PkgConfig::BULLET)
  # Bullet's headers are not -Werror clean: the peer's file is built without it.
  set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/bullet_soft.cpp PROPERTIES COMPILE_OPTIONS "-Wno-error;-w")
  add_test(NAME bench_bullet_smoke COMMAND bench_bullet --quick)
  set_tests_properties(bench_bullet_smoke PROPERTIES LABELS bench TIMEOUT 120
    ENVIRONMENT "VISCERA_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
else()
  message(STATUS "bench_bullet: not built (needs libbullet-dev and a C++ compiler)")
endif()
