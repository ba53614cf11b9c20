/* The links tase-sim makes (--link PATH, --klv-link PATH) and the check
 * that keeps the tools off a stale one (toolkit.h, "tase-sim's links").
 * Also compiled into the Python package (python/tase/_build.py), so
 * tase.connect() refuses what `tase` refuses: no exit, no stdio here.
 *
 * A link is a symlink PATH -> /dev/pts/N. Beside it tase-sim keeps
 * PATH.lock, a regular file holding one line, "tase-sim PID /dev/pts/N",
 * and holds a POSIX record lock (fcntl F_SETLK, whole file) on it for its
 * whole life. A tase-sim killed with SIGKILL leaves both behind, and
 * /dev/pts/N may be given to the next program that asks for a pty (a
 * terminal, another tase-sim): a tool that opened PATH then would write
 * gimbal commands into that program.
 *
 * Why a lock, not the times of the link and the pty node (a node made
 * after the link is a reused pty): the kernel releases a process's locks
 * when it ends, however it ends, so "held" means "a live process" on any
 * filesystem and whatever the clocks; a node's ctime moves with a chmod or
 * chown of the pty (mesg, a terminal emulator), and timestamps are as
 * coarse as the filesystem keeps them. Why fcntl and not flock: F_GETLK
 * names the holder's pid, so a reader can tell that the record was
 * written by the process that holds the lock (a new tase-sim taking over a
 * stale link holds the lock while the record still names the dead one's
 * pty), and a refused simulator names the owner. A POSIX lock is dropped
 * when its process closes any descriptor of the file: tase-sim opens each
 * lock file once and keeps that descriptor. Nothing of this is in the
 * library or its port API: it is the tools' own convention. */
#define _GNU_SOURCE /* O_NOFOLLOW, O_CLOEXEC with older glibc */

#include "toolkit.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <unistd.h>

#define RECORD_TAG "tase-sim "

int tk_simlink_lock_path(const char *link, char *out, size_t cap)
{
    int n = snprintf(out, cap, "%s%s", link, TK_SIMLINK_LOCK_SUFFIX);
    if (n < 0 || (size_t)n >= cap) {
        errno = ENAMETOOLONG;
        return -1;
    }
    return 0;
}

/* The pid of a process holding a lock on fd's file, 0 if none. */
static long lock_holder(int fd)
{
    struct flock fl;
    memset(&fl, 0, sizeof(fl));
    fl.l_type = F_WRLCK;
    fl.l_whence = SEEK_SET;
    if (fcntl(fd, F_GETLK, &fl) != 0 || fl.l_type == F_UNLCK) {
        return 0;
    }
    return fl.l_pid > 0 ? (long)fl.l_pid : -1; /* held by a process we cannot see */
}

/* The record of a lock file: 1 (pid and pty path set), 0 for an empty
 * file, -1 for anything else (not tase-sim's). */
static int read_record(int fd, long *pid, char *slave, size_t cap)
{
    char buf[256], *end;
    ssize_t n = pread(fd, buf, sizeof(buf) - 1u, 0);
    size_t len;
    if (n == 0) {
        return 0;
    }
    if (n < 0 || (size_t)n >= sizeof(buf) - 1u || buf[n - 1] != '\n') {
        return -1;
    }
    buf[n - 1] = '\0';
    if (strncmp(buf, RECORD_TAG, sizeof(RECORD_TAG) - 1u) != 0) {
        return -1;
    }
    errno = 0;
    *pid = strtol(buf + sizeof(RECORD_TAG) - 1u, &end, 10);
    if (errno != 0 || *pid <= 0 || *end != ' ') {
        return -1;
    }
    len = strlen(end + 1);
    if (len == 0u || len >= cap) {
        return -1;
    }
    memcpy(slave, end + 1, len + 1u);
    return 1;
}

int tk_simlink_claim(const char *link, char *why, size_t cap)
{
    char lock[PATH_MAX];
    int attempt;
    if (tk_simlink_lock_path(link, lock, sizeof(lock)) != 0) {
        snprintf(why, cap, "cannot claim %s: %s", link, strerror(errno));
        return -1;
    }
    /* The lock file may be removed by the tase-sim that held it (at its
     * exit) between our open and our lock: then the lock taken is on a
     * file nobody else sees, and we start again. */
    for (attempt = 0; attempt < 8; attempt++) {
        struct flock fl;
        struct stat a, b;
        long pid = 0;
        char slave[PATH_MAX];
        int rec;
        /* made by us (O_EXCL), or found: a file found empty is either
         * another simulator's that it has not locked and written yet (it
         * does both at once), or a user's own: never ours to take */
        int fd = open(lock, O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_NOCTTY | O_CLOEXEC, 0644);
        bool created = fd >= 0;
        if (fd < 0 && errno == EEXIST) {
            fd = open(lock, O_RDWR | O_NOFOLLOW | O_NOCTTY | O_CLOEXEC);
        }
        if (fd < 0) {
            snprintf(why, cap, "cannot claim %s: cannot open its lock file %s: %s", link, lock,
                     strerror(errno));
            return -1;
        }
        if (fstat(fd, &a) != 0 || !S_ISREG(a.st_mode)) {
            (void)close(fd);
            snprintf(why, cap, "%s exists and is not a lock file of tase-sim; not using %s", lock,
                     link);
            return -1;
        }
        memset(&fl, 0, sizeof(fl));
        fl.l_type = F_WRLCK;
        fl.l_whence = SEEK_SET;
        if (fcntl(fd, F_SETLK, &fl) != 0) {
            int e = errno;
            if (e == EACCES || e == EAGAIN) {
                pid = lock_holder(fd);
                (void)close(fd);
                snprintf(why, cap,
                         "%s is the link of a running tase-sim (pid %ld); not taking it over", link,
                         pid);
                return -1;
            }
            (void)close(fd);
            snprintf(why, cap, "cannot claim %s: cannot lock %s: %s", link, lock, strerror(e));
            return -1;
        }
        if (stat(lock, &b) != 0 || a.st_dev != b.st_dev || a.st_ino != b.st_ino) {
            (void)close(fd); /* removed or replaced meanwhile */
            continue;
        }
        rec = read_record(fd, &pid, slave, sizeof(slave));
        if (rec < 0 || (rec == 0 && !created)) {
            (void)close(fd);
            if (rec == 0 && attempt < 7) {
                struct timespec ts = {0, 20000000}; /* another simulator's, not written yet? */
                nanosleep(&ts, NULL);
                continue;
            }
            /* someone's own file of that name: never overwritten */
            snprintf(why, cap, "%s exists and is not a lock file of tase-sim; not using %s", lock,
                     link);
            return -1;
        }
        /* ours now: readable by every user's tools (a umask of 077 made
         * it unreadable to them, and a tool that cannot read it cannot
         * tell a stale link), and at once a record of a simulator starting
         * (no pty yet), so that a tool never takes the dead one's record
         * for ours */
        (void)fchmod(fd, 0644);
        if (tk_simlink_record(fd, TK_SIMLINK_STARTING) != 0) {
            int e = errno;
            (void)close(fd);
            snprintf(why, cap, "cannot claim %s: cannot write %s: %s", link, lock, strerror(e));
            return -1;
        }
        return fd;
    }
    snprintf(why, cap, "cannot claim %s: its lock file %s keeps changing", link, lock);
    return -1;
}

int tk_simlink_record(int fd, const char *slave)
{
    char buf[PATH_MAX + 32];
    int n = snprintf(buf, sizeof(buf), RECORD_TAG "%ld %s\n", (long)getpid(), slave);
    if (n < 0 || (size_t)n >= sizeof(buf)) {
        errno = ENAMETOOLONG;
        return -1;
    }
    /* one write: a reader sees the file empty or whole (the link does not
     * exist meanwhile, tk_pty_open()) */
    if (ftruncate(fd, 0) != 0 || pwrite(fd, buf, (size_t)n, 0) != (ssize_t)n) {
        return -1;
    }
    return 0;
}

void tk_simlink_release(const char *link, int fd)
{
    char lock[PATH_MAX];
    struct stat a, b;
    /* only the file we hold (not one a later simulator made after ours
     * was removed by someone) */
    if (tk_simlink_lock_path(link, lock, sizeof(lock)) == 0 && fstat(fd, &a) == 0 &&
        stat(lock, &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino) {
        (void)unlink(lock);
    }
    (void)close(fd);
}

/* One symlink `link` (reached from `given`) leading to `target`: -1 with
 * the reason when it is a tase-sim link whose simulator is gone (or one
 * whose simulator is starting or taking it over: the link may still lead
 * to the dead one's pty). Whether the simulator lives is whether anyone
 * holds the lock: no pid is compared (a simulator in another pid
 * namespace records a pid the tool's namespace does not know). */
static int check_one(const char *given, const char *link, int dir, const char *name,
                     const char *target, char *why, size_t cap)
{
    char lock[PATH_MAX], slave[PATH_MAX], through[PATH_MAX + 16], lockname[NAME_MAX + 8];
    struct stat st;
    long pid = 0, holder;
    int fd, rec;
    /* opened beside the link through its directory: LINK.lock as one path
     * may be too long where LINK is not (a path near PATH_MAX, "/./././"),
     * which passed a stale link unchecked */
    if ((size_t)snprintf(lockname, sizeof(lockname), "%s%s", name, TK_SIMLINK_LOCK_SUFFIX) >=
        sizeof(lockname)) {
        return 0; /* a name no lock file can have: not tase-sim's link */
    }
    /* for messages (shortened if need be) */
    if (snprintf(lock, sizeof(lock), "%s%s", link, TK_SIMLINK_LOCK_SUFFIX) < 0) {
        strcpy(lock, lockname);
    }
    through[0] = '\0';
    if (strcmp(given, link) != 0) {
        snprintf(through, sizeof(through), " (through %s)", link);
    }
    fd = openat(dir, lockname, O_RDONLY | O_NOFOLLOW | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        if (errno == EACCES) {
            /* a simulator's lock file we may not read: whether its
             * simulator lives cannot be told, so not opened */
            snprintf(why, cap,
                     "%s%s: cannot read %s (%s), so whether the tase-sim of this link still runs "
                     "cannot be told; not opened, nothing sent",
                     given, through, lock, strerror(errno));
            return -1;
        }
        return 0; /* no lock file: not a link of tase-sim (socat's, a user's) */
    }
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        (void)close(fd);
        return 0;
    }
    rec = read_record(fd, &pid, slave, sizeof(slave));
    holder = lock_holder(fd);
    (void)close(fd);
    if (rec < 0 || (rec == 0 && holder == 0)) {
        return 0; /* not tase-sim's (a user's file of that name) */
    }
    if (rec == 0 || (strcmp(slave, TK_SIMLINK_STARTING) == 0 && holder != 0)) {
        snprintf(why, cap,
                 "%s%s: a tase-sim is starting on this link (pid %ld); not opened, nothing sent "
                 "(try again)",
                 given, through, holder);
        return -1;
    }
    if (strcmp(slave, TK_SIMLINK_STARTING) != 0 && strcmp(slave, target) != 0) {
        /* the link leads elsewhere now (repointed by someone: not the
         * pty the record is about) */
        return 0;
    }
    if (holder == 0) {
        snprintf(why, cap,
                 "%s%s is the link of a tase-sim that is no longer running (pid %ld, killed?): "
                 "%s may belong to another program now; not opened, nothing sent (start "
                 "tase-sim again, or remove %s and %s)",
                 given, through, pid, target, link, lock);
        return -1;
    }
    return 0;
}

/* The directory of path (relative to at) opened for the *at() calls, and
 * its last name in name; -1 if there is none to check. */
static int open_parent(int at, const char *path, char *name, size_t cap)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash == NULL ? path : slash + 1;
    char dir[PATH_MAX];
    if (*base == '\0' || strlen(base) >= cap || strlen(path) >= sizeof(dir)) {
        return -1;
    }
    strcpy(name, base);
    if (slash == NULL) {
        strcpy(dir, ".");
    } else if (slash == path) {
        strcpy(dir, "/");
    } else {
        memcpy(dir, path, (size_t)(slash - path));
        dir[slash - path] = '\0';
    }
    return openat(at, dir, O_PATH | O_DIRECTORY | O_CLOEXEC);
}

int tk_simlink_check(const char *path, char *why, size_t cap)
{
    char cur[PATH_MAX], target[PATH_MAX], name[NAME_MAX + 1];
    unsigned hops;
    int rc = 0, dir;
    if (strlen(path) >= sizeof(cur)) {
        return 0; /* the open will say what is wrong with it */
    }
    strcpy(cur, path);
    /* every symlink on the way: a user's link to a tase-sim link counts.
     * Followed as the kernel follows them, each from the directory of the
     * link before (no path joined: one too long for a string is not too
     * long for the open); cur is the link as shown in messages. */
    dir = open_parent(AT_FDCWD, path, name, sizeof(name));
    for (hops = 0; dir >= 0 && hops < 40u; hops++) {
        struct stat st;
        ssize_t n;
        int next;
        if (fstatat(dir, name, &st, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISLNK(st.st_mode)) {
            break;
        }
        n = readlinkat(dir, name, target, sizeof(target) - 1u);
        if (n <= 0 || (size_t)n >= sizeof(target) - 1u) {
            break;
        }
        target[n] = '\0';
        if (check_one(path, cur, dir, name, target, why, cap) != 0) {
            rc = -1;
            break;
        }
        next = open_parent(target[0] == '/' ? AT_FDCWD : dir, target, name, sizeof(name));
        (void)close(dir);
        dir = next;
        if (target[0] == '/') {
            strcpy(cur, target);
        } else {
            /* relative to the directory of the link (shortened if need be) */
            char shown[PATH_MAX];
            const char *slash = strrchr(cur, '/');
            int w = slash == NULL ? snprintf(shown, sizeof(shown), "%s", target)
                                  : snprintf(shown, sizeof(shown), "%.*s/%s", (int)(slash - cur),
                                             cur, target);
            strcpy(cur, w < 0 ? target : shown);
        }
    }
    if (dir >= 0) {
        (void)close(dir);
    }
    return rc;
}
