/* The fmi2CallbackLogger handed to FMUs. FMI 2.0 (2.1.5) makes `message` a printf format
 * with variadic arguments, so it can only be expanded in C. This one is defensive: NULL
 * strings are tolerated, a format containing a %n conversion (which would make vsnprintf
 * write through an argument the FMU never meant as a pointer) is passed on unexpanded, and the
 * expanded text is capped at MASTER_LOG_MAX bytes. The text goes to master_fmi2_log (Rust),
 * which never unwinds into the FMU. */
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

#define MASTER_LOG_MAX 65536

extern void master_fmi2_log(void *environment, const char *instance, int status,
                            const char *category, const char *text, size_t length,
                            int expanded);

/* Whether the format has a %n conversion (any flags, width, precision or length before it). */
static int has_percent_n(const char *format) {
  for (const char *p = format; *p; ++p) {
    if (*p != '%') continue;
    ++p;
    if (*p == '%') continue;
    while (*p && (*p == '-' || *p == '+' || *p == ' ' || *p == '#' || *p == '0' ||
                  *p == '\'' || *p == '*' || *p == '.' || *p == '$' ||
                  (*p >= '1' && *p <= '9') || *p == 'h' || *p == 'l' || *p == 'L' ||
                  *p == 'q' || *p == 'j' || *p == 'z' || *p == 't'))
      ++p;
    if (*p == 'n') return 1;
    if (!*p) break;
  }
  return 0;
}

static size_t bounded_length(const char *s) {
  size_t n = 0;
  while (n < MASTER_LOG_MAX && s[n]) ++n;
  return n;
}

void master_fmi2_logger(void *environment, const char *instance, int status,
                        const char *category, const char *message, ...) {
  if (message == NULL) {
    master_fmi2_log(environment, instance, status, category, "", 0, 0);
    return;
  }
  if (has_percent_n(message)) {
    master_fmi2_log(environment, instance, status, category, message,
                    bounded_length(message), 0);
    return;
  }
  char small[1024];
  va_list args;
  va_start(args, message);
  int n = vsnprintf(small, sizeof small, message, args);
  va_end(args);
  if (n < 0) {
    master_fmi2_log(environment, instance, status, category, message,
                    bounded_length(message), 0);
    return;
  }
  if ((size_t)n < sizeof small) {
    master_fmi2_log(environment, instance, status, category, small, (size_t)n, 1);
    return;
  }
  size_t size = (size_t)n < MASTER_LOG_MAX ? (size_t)n + 1 : MASTER_LOG_MAX + 1;
  char *big = malloc(size);
  if (big == NULL) {
    master_fmi2_log(environment, instance, status, category, small, sizeof small - 1, 1);
    return;
  }
  va_start(args, message);
  int m = vsnprintf(big, size, message, args);
  va_end(args);
  size_t length = m < 0 ? 0 : ((size_t)m < size ? (size_t)m : size - 1);
  master_fmi2_log(environment, instance, status, category, big, length, 1);
  free(big);
}
