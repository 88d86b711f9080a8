/* File operations the output writer needs and Fortran lacks: an exclusive lock on a lock
 * file (flock, released by the kernel when the process dies), unlink, and the text of an
 * errno. No state: every function works on its arguments only (the library's rule). */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

/* fd_lock_acquire: the lock path is not a regular file (a symbolic link, a directory, ...). */
#define FD_LOCK_NOT_FILE (-1)

/* Take an exclusive lock on the file `path` (created if missing); on success *fd holds the
 * descriptor to pass to fd_lock_release and 0 is returned, else errno, or FD_LOCK_NOT_FILE
 * when `path` is a symbolic link or anything but a regular file (a link planted there
 * would make the writer create or lock a file elsewhere: it is never followed). A lock file
 * is removed on release; a waiter that got the lock on a file removed meanwhile retries on
 * the new one, so two processes never both hold "the" lock. */
int fd_lock_acquire(const char *path, int *fd)
{
    for (;;) {
        struct stat held, now;
        int f = open(path, O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0644);
        if (f < 0) {
            int e = errno;
            struct stat ls;
            if (e == ELOOP || e == EISDIR || e == ENXIO ||
                (lstat(path, &ls) == 0 && !S_ISREG(ls.st_mode)))
                return FD_LOCK_NOT_FILE;
            return e;
        }
        if (fstat(f, &held) != 0 || !S_ISREG(held.st_mode)) {
            close(f);
            return FD_LOCK_NOT_FILE;
        }
        while (flock(f, LOCK_EX) != 0) {
            if (errno != EINTR) {
                int e = errno;
                close(f);
                return e;
            }
        }
        if (lstat(path, &now) == 0 && held.st_ino == now.st_ino && held.st_dev == now.st_dev) {
            *fd = f;
            return 0;
        }
        close(f); /* the file was replaced while we waited: lock the current one */
    }
}

/* Remove the lock file and release the lock. */
int fd_lock_release(const char *path, int fd)
{
    int e = unlink(path) == 0 ? 0 : errno;
    close(fd);
    return e;
}

/* mkdir(path, 0755): 0, or errno (EEXIST included). */
int fd_mkdir(const char *path)
{
    return mkdir(path, 0755) == 0 ? 0 : errno;
}

/* unlink(path): 0, or errno (ENOENT included). */
int fd_unlink(const char *path)
{
    return unlink(path) == 0 ? 0 : errno;
}

/* rename(from, to): 0, or errno. */
int fd_rename(const char *from, const char *to)
{
    return rename(from, to) == 0 ? 0 : errno;
}

/* The text of errno `err` into buf (NUL-terminated, at most len bytes). */
void fd_errno_text(int err, char *buf, int len)
{
    char tmp[256];
    const char *m = strerror_r(err, tmp, sizeof tmp);
    snprintf(buf, (size_t)len, "%s", m);
}

/* The process id, for temporary names unique per process. */
int fd_getpid(void)
{
    return (int)getpid();
}

/* Create a new file for writing (O_EXCL: EEXIST when the name exists); *fd on success. */
int fd_file_create(const char *path, int *fd)
{
    int f = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (f < 0)
        return errno;
    *fd = f;
    return 0;
}

/* Write len bytes; 0 or errno (ENOSPC, EDQUOT, EIO, ...). gfortran's formatted writes
 * lose these errors (a full disk gave a truncated file and iostat = 0), hence this. */
int fd_file_write(int fd, const char *buf, long len)
{
    while (len > 0) {
        ssize_t n = write(fd, buf, (size_t)len);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            return errno;
        }
        buf += n;
        len -= n;
    }
    return 0;
}

/* fsync (the data is on disk before the file is renamed into place; NFS reports a full
 * disk or quota here at the latest) and close; 0 or the first errno. */
int fd_file_close(int fd)
{
    int e = 0;
    if (fsync(fd) != 0 && errno != EINVAL && errno != EROFS)
        e = errno;
    if (close(fd) != 0 && e == 0)
        e = errno;
    return e;
}
