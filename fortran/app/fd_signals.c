/* Signal handling of the frictiondyn program (not of the library): the temporary output
 * files being written are process-global state, kept here. On SIGINT, SIGTERM, SIGHUP or
 * SIGXCPU (Slurm's time limit sends SIGTERM) the registered temporary files are removed and
 * the signal is raised again with its default action, so the exit status tells the shell
 * (and Slurm) how the run ended. SIGXFSZ (a file-size limit, `ulimit -f`, reached) is
 * ignored: the write then fails with EFBIG and the run ends with the writer's usual
 * "cannot write" error, its temporary files removed, instead of being killed. */
#define _GNU_SOURCE
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define FD_MAX_TEMPS 2
#define FD_PATH_MAX 4096

static char temp_path[FD_MAX_TEMPS][FD_PATH_MAX];
static volatile sig_atomic_t n_temps = 0;

static void on_signal(int sig)
{
    for (int i = 0; i < n_temps; i++)
        unlink(temp_path[i]); /* async-signal-safe */
    signal(sig, SIG_DFL);
    raise(sig);
}

/* Install the handlers (once, at start). */
void fd_app_install_signal_handlers(void)
{
    static const int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGXCPU};
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigfillset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++)
        sigaction(sigs[i], &sa, NULL);
    signal(SIGXFSZ, SIG_IGN);
}

/* Register the temporary files a signal must remove ("" for none). Returns 1 when a path
 * is too long to keep. The count is set last, so a signal never sees a half-copied name. */
int fd_app_register_temps(const char *a, const char *b)
{
    n_temps = 0;
    if (strlen(a) >= FD_PATH_MAX || strlen(b) >= FD_PATH_MAX)
        return 1;
    strcpy(temp_path[0], a);
    strcpy(temp_path[1], b);
    n_temps = 2;
    return 0;
}

/* No temporary file any more (committed or removed). */
void fd_app_clear_temps(void)
{
    n_temps = 0;
}
