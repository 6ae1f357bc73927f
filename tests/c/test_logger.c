#include <stdarg.h>
#include <stdio.h>

typedef void (*record_fn)(void *env, const char *instance, unsigned int status,
                          const char *category, const char *format, const char *message);

/* The environment pointer handed to the FMU points to this struct. */
typedef struct {
    record_fn record;
    void *rust_state;
} test_env;

void test_logger(void *env, const char *instance, unsigned int status, const char *category,
                 const char *format, ...) {
    char buffer[8192];
    va_list args;
    va_start(args, format);
    vsnprintf(buffer, sizeof buffer, format ? format : "(null format)", args);
    va_end(args);
    test_env *e = (test_env *)env;
    if (e && e->record) {
        e->record(env, instance, status, category, format, buffer);
    }
}
