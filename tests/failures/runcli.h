/* runcli.h — run the flexmbd command line as a child process (the contract under test is the
 * program's: exit code, stderr lines, the CSV it leaves), with its stderr in a file and its
 * resource use (peak RSS) from wait4. Header-only; used by test_failures.c and test_long_run.c. */
#ifndef FLEXMBD_RUNCLI_H
#define FLEXMBD_RUNCLI_H

#include <fcntl.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

typedef struct {
  int exit_code;  /* -1 if killed by a signal */
  int signal;     /* the signal, or 0 */
  long maxrss_kb; /* peak resident set size of the child */
  char* err;      /* whole stderr, NUL-terminated (malloc) */
} runcliResult;

/* argv: NULL-terminated, argv[0] the program. stderr goes to err_path and is read back. */
static int runcli(char* const* argv, const char* err_path, runcliResult* r) {
  memset(r, 0, sizeof *r);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid;
  int rc = posix_spawn(&pid, argv[0], &fa, NULL, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) {
    fprintf(stderr, "cannot start %s: %s\n", argv[0], strerror(rc));
    return -1;
  }
  int status = 0;
  struct rusage ru;
  if (wait4(pid, &status, 0, &ru) != pid) return -1;
  r->maxrss_kb = ru.ru_maxrss;
  if (WIFEXITED(status)) {
    r->exit_code = WEXITSTATUS(status);
  } else {
    r->exit_code = -1;
    r->signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  }
  FILE* f = fopen(err_path, "rb");
  if (!f) return -1;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  rewind(f);
  r->err = calloc((size_t)n + 1, 1);
  if (r->err && n > 0 && fread(r->err, 1, (size_t)n, f) != (size_t)n) n = 0;
  fclose(f);
  return r->err ? 0 : -1;
}

/* the value of `key=` in the stats line (the last "stats:" line), or NAN */
static double runcli_stat(const runcliResult* r, const char* key) {
  const char* line = NULL;
  for (const char* s = r->err; (s = strstr(s, "stats: ")) != NULL; ++s) line = s;
  if (!line) return 0.0 / 0.0;
  char pat[64];
  snprintf(pat, sizeof pat, " %s=", key);
  const char* v = strstr(line, pat);
  return v ? strtod(v + strlen(pat), NULL) : 0.0 / 0.0;
}

#endif
