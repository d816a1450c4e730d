/* SPDX-License-Identifier: Apache-2.0 */
#include "build_id.h"

#ifndef VISCERA_BUILD_FLAGS
#define VISCERA_BUILD_FLAGS "unknown"
#endif

const char *build_compiler(void) {
#if defined(__clang__)
  return "clang " __clang_version__;
#elif defined(__GNUC__)
  return "gcc " __VERSION__;
#else
  return "unknown compiler";
#endif
}

const char *build_flags(void) { return VISCERA_BUILD_FLAGS; }
