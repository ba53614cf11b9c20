/* A preloaded shim for tests/tools/e2e.sh (LD_PRELOAD) that raises a signal
 * at the worst moment for a program, which a scheduler gives only now and
 * then. TASE_TEST_SIGNAL holds the signal's number, and
 *   TASE_TEST_SIGNAL_AFTER_SYMLINK=1  raises it once, right after the first
 *       symlink() that succeeds (tase-sim's link made, not yet recorded: a
 *       SIGUSR1 sent as soon as the link appeared left it behind in CI);
 *   TASE_TEST_SIGNAL_BEFORE_TCSETATTR=K  raises it right before the K-th
 *       tcsetattr() (a tool's 2nd gives its serial line's settings back as
 *       the link closes);
 *   TASE_TEST_SIGNAL_AFTER_CREATE=TEXT  raises it once, right after the
 *       first open() with O_CREAT of a path containing TEXT that succeeds
 *       (a capture file made, its header not yet written).
 * The calls themselves are libc's (dlsym(RTLD_NEXT)). */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <fcntl.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <termios.h>
#include <unistd.h>

static int wanted(const char *name)
{
    const char *v = getenv(name);
    return v != NULL ? atoi(v) : 0;
}

static void raise_it(void)
{
    (void)raise(wanted("TASE_TEST_SIGNAL"));
}

/* libc's definition of `name` (copied, not cast: ISO C has no conversion
 * from an object pointer to a function pointer) */
static void next_of(const char *name, void *fn, size_t size)
{
    void *p = dlsym(RTLD_NEXT, name);
    if (p == NULL) {
        abort();
    }
    memcpy(fn, &p, size);
}

/* declared by <unistd.h>; preloaded, this definition is found before libc's */
int symlink(const char *target, const char *linkpath)
{
    static int raised;
    int (*real)(const char *, const char *);
    int r;
    next_of("symlink", &real, sizeof(real));
    r = real(target, linkpath);
    if (r == 0 && wanted("TASE_TEST_SIGNAL_AFTER_SYMLINK") && !raised) {
        raised = 1;
        raise_it();
    }
    return r;
}

/* declared by <termios.h> */
int tcsetattr(int fd, int when, const struct termios *t)
{
    static int calls;
    int (*real)(int, int, const struct termios *);
    next_of("tcsetattr", &real, sizeof(real));
    if (++calls == wanted("TASE_TEST_SIGNAL_BEFORE_TCSETATTR")) {
        raise_it();
    }
    return real(fd, when, t);
}

/* declared by <fcntl.h> */
int open(const char *path, int flags, ...)
{
    static int raised;
    int (*real)(const char *, int, ...);
    const char *text = getenv("TASE_TEST_SIGNAL_AFTER_CREATE");
    mode_t mode = 0;
    int fd;
    if ((flags & O_CREAT) != 0) {
        va_list ap;
        va_start(ap, flags);
        mode = (mode_t)va_arg(ap, unsigned int);
        va_end(ap);
    }
    next_of("open", &real, sizeof(real));
    fd = real(path, flags, mode);
    if (fd >= 0 && (flags & O_CREAT) != 0 && text != NULL && strstr(path, text) != NULL &&
        !raised) {
        raised = 1;
        raise_it();
    }
    return fd;
}
