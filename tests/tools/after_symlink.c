/* A preloaded shim for tests/tools/e2e.sh (LD_PRELOAD): symlink() makes the
 * link as libc's does, then, the first time it succeeds, raises the signal
 * whose number TASE_TEST_SIGNAL_AFTER_SYMLINK holds. That is the worst
 * moment for a program that records its links after making them, and a
 * scheduler gives it only now and then (a SIGUSR1 sent as soon as
 * tase-sim's link appeared left the link behind once in CI). */
#define _GNU_SOURCE
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/syscall.h>
#include <unistd.h>

/* declared by <unistd.h>; preloaded, this definition is found before libc's */
int symlink(const char *target, const char *linkpath)
{
    static int raised;
    const char *sig = getenv("TASE_TEST_SIGNAL_AFTER_SYMLINK");
    long r = syscall(SYS_symlinkat, target, AT_FDCWD, linkpath);
    if (r == 0 && sig != NULL && !raised) {
        raised = 1;
        (void)raise(atoi(sig));
    }
    return (int)r;
}
