/* SPDX-License-Identifier: Apache-2.0 */
/* test_tmpfile: temporary files of a test. Paths are
 * /tmp/viscera_test_<pid>_<name>, so parallel test runs do not collide;
 * the caller unlinks them. A file that cannot be written ends the test
 * (exit 1) naming the path: the checks after it would be meaningless.
 * Implemented in test_tmpfile.c (viscera_test_support). */
#ifndef VISCERA_TEST_TMPFILE_H
#define VISCERA_TEST_TMPFILE_H

/* The path of the temporary file `name`; valid until the fourth call of
 * test_tmp_path or test_write_tmp after this one. */
const char *test_tmp_path(const char *name);

/* Writes `text` to the temporary file `name`; returns its path (as
 * test_tmp_path). */
const char *test_write_tmp(const char *name, const char *text);

#endif
