/* SPDX-License-Identifier: Apache-2.0 */
/* build_id: which build this program is (issue 16: a recording names the
 * build that ran the session, because bit-exact re-simulation holds for
 * the same build only): the project version, the compiler and the flags
 * CMake configured. Constant strings. */
#ifndef VISCERA_BUILD_ID_H
#define VISCERA_BUILD_ID_H

/* e.g. "gcc 12.2.0" */
const char *build_compiler(void);
/* e.g. "Release -O2 werror=ON sanitize=OFF" */
const char *build_flags(void);

#endif
