/* Temporary output names and the removal of stale ones. A writer's temporary files are
 * named `.<file>.<tag>.tmp` beside their final name, with a tag `<pid>_<host>_<salt>` that
 * says which process on which machine writes them. A temporary whose process is gone (a run
 * killed by SIGKILL, the out-of-memory killer, a node failure: nothing could remove it) is
 * stale; one on another machine, or of a live process, is never touched. No state: every
 * function works on its arguments only (the library's rule). */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

/* This machine's name as it stands in a tag: '/', '.' and '_' become '-' (a tag is part of
 * a file name and its fields are separated by '_'). */
static void tag_host(char *host, size_t len)
{
    if (gethostname(host, len) != 0)
        snprintf(host, len, "host");
    host[len - 1] = '\0';
    for (char *c = host; *c; c++)
        if (*c == '/' || *c == '.' || *c == '_')
            *c = '-';
}

/* The tag `<pid>_<host>_<salt, hex>` into buf (NUL-terminated, at most len bytes). */
void fd_temp_tag(char *buf, int len, unsigned long long salt)
{
    char host[256];
    tag_host(host, sizeof host);
    snprintf(buf, (size_t)len, "%ld_%s_%llx", (long)getpid(), host, salt);
}

/* Whether the tag between prefix and ".tmp" in `name` is this machine's and its process
 * is gone. */
static int is_stale(const char *tag, size_t taglen, const char *host)
{
    char buf[512], *end;
    if (taglen == 0 || taglen >= sizeof buf)
        return 0;
    memcpy(buf, tag, taglen);
    buf[taglen] = '\0';
    errno = 0;
    long pid = strtol(buf, &end, 10);
    if (errno != 0 || end == buf || *end != '_' || pid <= 0)
        return 0;
    char *h = end + 1, *last = strrchr(h, '_');
    if (last == NULL || (size_t)(last - h) != strlen(host) || strncmp(h, host, (size_t)(last - h)) != 0)
        return 0; /* another machine's (or not a tag): its process cannot be asked */
    return kill((pid_t)pid, 0) != 0 && errno == ESRCH;
}

/* Remove the stale temporaries `.<base>.<tag>.tmp` of the file `path` (`<dir>/<base>`).
 * Returns how many were removed; nothing is an error here (a directory that cannot be read
 * is the writer's to report). */
int fd_remove_stale_temps(const char *path)
{
    char dir[4096], prefix[1024], host[256];
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    size_t dl = slash ? (size_t)(slash - path) : 0;
    if (dl >= sizeof dir || strlen(base) + 3 >= sizeof prefix)
        return 0;
    if (slash) {
        memcpy(dir, path, dl);
        dir[dl] = '\0';
        if (dl == 0)
            snprintf(dir, sizeof dir, "/");
    } else {
        snprintf(dir, sizeof dir, ".");
    }
    snprintf(prefix, sizeof prefix, ".%s.", base);
    tag_host(host, sizeof host);
    int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd < 0)
        return 0;
    DIR *d = fdopendir(dfd);
    if (d == NULL) {
        close(dfd);
        return 0;
    }
    int removed = 0;
    size_t pl = strlen(prefix);
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        size_t nl = strlen(e->d_name);
        if (nl < pl + 4 || strncmp(e->d_name, prefix, pl) != 0 || strcmp(e->d_name + nl - 4, ".tmp") != 0)
            continue;
        if (!is_stale(e->d_name + pl, nl - pl - 4, host))
            continue;
        struct stat st;
        if (fstatat(dfd, e->d_name, &st, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISREG(st.st_mode))
            continue;
        if (unlinkat(dfd, e->d_name, 0) == 0)
            removed++;
    }
    closedir(d);
    return removed;
}
