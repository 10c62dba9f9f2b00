/* Tiny check macros for iris's plain-C test executables: each failed check
 * prints file:line, the expression and both values, and is counted; a test's
 * main ends with `return TEST_SUMMARY();` (non-zero when anything failed).
 * A test that cannot run returns TEST_SKIP("why") (CTest SKIP_RETURN_CODE 77). */
#ifndef IRIS_TESTS_CHECK_H
#define IRIS_TESTS_CHECK_H

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IRIS_TEST_SKIP_CODE 77

/* Number of failed checks so far (shared by every file of one test executable). */
extern int iris_check_failures;
/* Number of checks run so far. */
extern long iris_check_count;

/* Records one check result; prints the message (printf-style) when it failed.
 * Returns ok so callers can branch on it. */
int iris_check_record(int ok, const char *file, int line, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
/* Prints "<n> checks, <k> failed" and returns 0 or 1 for main. */
int iris_check_summary(const char *name);

/* A fresh empty directory for one test's files (under $TMPDIR or /tmp). */
int iris_test_tmpdir(char *out, size_t size, const char *tag);
/* Removes a directory tree created by iris_test_tmpdir. */
void iris_test_rmtree(const char *path);
/* Number of entries of `dir` whose name contains `needle` (-1 if unreadable). */
int iris_test_count_entries(const char *dir, const char *needle);

#define CHECK(cond) iris_check_record(!!(cond), __FILE__, __LINE__, "CHECK(%s)", #cond)

#define CHECK_NEAR(a, b, tol)                                                                     \
  do {                                                                                            \
    double a_ = (double)(a), b_ = (double)(b), t_ = (double)(tol);                                \
    iris_check_record(fabs(a_ - b_) <= t_, __FILE__, __LINE__,                                    \
                      "CHECK_NEAR(%s, %s, %s): %.9g vs %.9g (diff %.3g > %.3g)", #a, #b, #tol, a_, \
                      b_, fabs(a_ - b_), t_);                                                     \
  } while (0)

#define CHECK_EQ_INT(a, b)                                                                 \
  do {                                                                                     \
    long long a_ = (long long)(a), b_ = (long long)(b);                                    \
    iris_check_record(a_ == b_, __FILE__, __LINE__, "CHECK_EQ_INT(%s, %s): %lld vs %lld", #a, \
                      #b, a_, b_);                                                         \
  } while (0)

#define CHECK_EQ_STR(a, b)                                                                 \
  do {                                                                                     \
    const char *a_ = (a), *b_ = (b);                                                       \
    iris_check_record(a_ && b_ && strcmp(a_, b_) == 0, __FILE__, __LINE__,                 \
                      "CHECK_EQ_STR(%s, %s): \"%s\" vs \"%s\"", #a, #b, a_ ? a_ : "(null)", \
                      b_ ? b_ : "(null)");                                                 \
  } while (0)

/* Checks that an iris call returned IRIS_OK; prints the error record if not. */
#define CHECK_OK(status, errp)                                                             \
  do {                                                                                     \
    iris_status s_ = (status);                                                             \
    char b_[1400] = "";                                                                    \
    if (s_ != IRIS_OK) iris_error_format((errp), b_, sizeof b_);                           \
    iris_check_record(s_ == IRIS_OK, __FILE__, __LINE__, "CHECK_OK(%s): %s: %s", #status,  \
                      iris_status_name(s_), b_);                                           \
  } while (0)

#define TEST_SUMMARY() iris_check_summary(__FILE__)
#define TEST_SKIP(why)                                           \
  (printf("SKIP %s: %s\n", __FILE__, (why)), fflush(stdout), IRIS_TEST_SKIP_CODE)

#ifdef __cplusplus
}
#endif
#endif
