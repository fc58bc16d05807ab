/* run_serve.c — `flexmbd run SCENE --serve [--set PATH=VALUE]... [--plugin x.so]...`: a runner
 * that stays, for `flexmbd sweep --runner serve` (docs/sweep.md). Each request on fd 3
 * (serve_protocol.h: length-prefixed fields, the run's CSV and its overrides) asks for one run of
 * the scene; it is loaded and run exactly as `flexmbd run SCENE -o OUT.csv --quiet --set ...`
 * would (the same fmb_load and fmb_run), and one answer goes to fd 4 (the exit code, the stats
 * line, the message, under the request's number). stdout is not the channel: what a plugin
 * prints there cannot be read as an answer. Ends at the end of the requests.
 * What it saves is the process start of each run (exec and linking: ~3 ms of CPU per run, as
 * much as a four-bar run computes); what it gives up is a fresh process per run: a crash or a
 * hang ends the runner, which the sweep records for the run in flight and replaces. */
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "serve_protocol.h"

char* fmb_serve_request(uint64_t seq, const char* const* fields, int n, size_t* len) {
  size_t cap = 64;
  for (int k = 0; k < n; ++k) cap += strlen(fields[k]) + 24;
  char* buf = malloc(cap);
  if (!buf) return NULL;
  size_t at = (size_t)snprintf(buf, cap, "Q %" PRIu64 " %d\n", seq, n);
  for (int k = 0; k < n; ++k) {
    const size_t l = strlen(fields[k]);
    at += (size_t)snprintf(buf + at, cap - at, "%zu:", l);
    memcpy(buf + at, fields[k], l);
    at += l;
    buf[at++] = '\n';
  }
  *len = at;
  return buf;
}

void fmb_serve_free_fields(char** fields, int n) {
  for (int k = 0; fields && k < n; ++k) free(fields[k]);
  free(fields);
}

/* a decimal number up to `stop` from in; 0 or -1 */
static int read_number(FILE* in, char stop, unsigned long long* v, int* eof) {
  int c, digits = 0;
  *v = 0;
  while ((c = getc(in)) != EOF && c >= '0' && c <= '9' && digits < 19) *v = *v * 10 + (unsigned)(c - '0'), ++digits;
  if (c == EOF && eof) *eof = digits == 0;
  return digits > 0 && c == stop ? 0 : -1;
}

int fmb_serve_read_request(FILE* in, uint64_t* seq, char*** fields, int* n) {
  *fields = NULL, *n = 0;
  int c = getc(in);
  if (c == EOF) return 0;
  unsigned long long s, count;
  if (c != 'Q' || getc(in) != ' ' || read_number(in, ' ', &s, NULL) || read_number(in, '\n', &count, NULL) ||
      count > FMB_SERVE_MAX_FIELDS)
    return -1;
  char** f = calloc(count ? count : 1, sizeof *f);
  if (!f) return -1;
  for (unsigned long long k = 0; k < count; ++k) {
    unsigned long long l;
    if (read_number(in, ':', &l, NULL) || l > FMB_SERVE_MAX_FIELD || !(f[k] = malloc(l + 1)) ||
        fread(f[k], 1, l, in) != l || getc(in) != '\n') {
      fmb_serve_free_fields(f, (int)count);
      return -1;
    }
    f[k][l] = '\0';
    if (strlen(f[k]) != l) { /* a NUL inside a field: not a name nor an override */
      fmb_serve_free_fields(f, (int)count);
      return -1;
    }
  }
  *seq = s, *fields = f, *n = (int)count;
  return 1;
}

size_t fmb_serve_answer(char* buf, uint64_t seq, int exit_code, const char* stats, const char* msg) {
  size_t ls = strlen(stats), lm = strlen(msg);
  if (ls > 2000) ls = 2000;
  if (lm > FMB_SERVE_MAX_ANSWER - 2200) lm = FMB_SERVE_MAX_ANSWER - 2200;
  size_t at = (size_t)snprintf(buf, 128, "A %" PRIu64 " %d %zu %zu\n", seq, exit_code, ls, lm);
  memcpy(buf + at, stats, ls);
  memcpy(buf + at + ls, msg, lm);
  return at + ls + lm;
}

long fmb_serve_parse_answer(const char* buf, size_t n, uint64_t* seq, int* exit_code, char* stats, size_t nstats,
                            char* msg, size_t nmsg) {
  const char* nl = memchr(buf, '\n', n < 128 ? n : 128);
  if (!nl) return n < 128 ? 0 : -1;
  char head[128];
  memcpy(head, buf, (size_t)(nl - buf));
  head[nl - buf] = '\0';
  unsigned long long s, ls, lm;
  int rc, used = 0;
  if (sscanf(head, "A %llu %d %llu %llu%n", &s, &rc, &ls, &lm, &used) != 4 || head[used] ||
      ls + lm > FMB_SERVE_MAX_ANSWER)
    return -1;
  const size_t total = (size_t)(nl - buf) + 1 + ls + lm;
  if (n < total) return 0;
  const char* body = nl + 1;
  snprintf(stats, nstats, "%.*s", (int)ls, body);
  snprintf(msg, nmsg, "%.*s", (int)lm, body + ls);
  *seq = s, *exit_code = rc;
  return (long)total;
}

static int write_all(int fd, const char* s, size_t n) {
  while (n > 0) {
    const ssize_t w = write(fd, s, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return -1;
    s += w, n -= (size_t)w;
  }
  return 0;
}

int fmb_run_serve(const fmbCliScene* s) {
  FILE* in = fcntl(FMB_SERVE_ANSWER_FD, F_GETFD) >= 0 ? fdopen(FMB_SERVE_REQUEST_FD, "r") : NULL;
  if (!in) {
    fprintf(stderr,
            "flexmbd run --serve: expects requests on fd %d and answers on fd %d (it is started by "
            "`flexmbd sweep --runner serve`)\n",
            FMB_SERVE_REQUEST_FD, FMB_SERVE_ANSWER_FD);
    return FMB_EXIT_BAD_INPUT;
  }
  fcntl(FMB_SERVE_REQUEST_FD, F_SETFD, FD_CLOEXEC);
  fcntl(FMB_SERVE_ANSWER_FD, F_SETFD, FD_CLOEXEC);
  const char* sets[FMB_CLI_MAX_OVERRIDES + FMB_SERVE_MAX_FIELDS];
  uint64_t seq;
  char** field;
  int nfield, got;
  while ((got = fmb_serve_read_request(in, &seq, &field, &nfield)) != 0) {
    if (got < 0) {
      fprintf(stderr, "flexmbd run --serve: a malformed request: stopping\n");
      return FMB_EXIT_BAD_INPUT;
    }
    int n = 0;
    for (int k = 0; k < s->nover; ++k) sets[n++] = s->overrides[k];
    const char* out = nfield > 0 && field[0][0] ? field[0] : NULL;
    for (int k = 1; k < nfield; ++k) sets[n++] = field[k];
    fmbDiag diag;
    memset(&diag, 0, sizeof diag);
    fmbStats stats;
    memset(&stats, 0, sizeof stats);
    char msg[sizeof diag.file + sizeof diag.msg + 64] = "";
    int rc;
    fmbModel* m = out ? fmb_load(s->scene, sets, n, fmb_cli_registry(), &diag) : NULL;
    if (!m) {
      rc = diag.code ? diag.code : FMB_EXIT_BAD_INPUT;
      if (out)
        fmb_cli_format_diag(&diag, msg, sizeof msg);
      else
        snprintf(msg, sizeof msg, "error: a request without an output file");
    } else {
      fmbRunOptions opt = {.csv_path = out, .quiet = 1};
      rc = fmb_run(m, &opt, &stats, &diag);
      if (rc) fmb_cli_format_diag(&diag, msg, sizeof msg);
      fmb_free(m);
    }
    fmb_serve_free_fields(field, nfield);
    char* text = NULL;
    size_t len = 0;
    FILE* ms = open_memstream(&text, &len);
    if (ms) {
      fmb_print_stats(&stats, ms); /* the stats line of `flexmbd run`, the same function */
      fclose(ms);
    }
    if (text && len && text[len - 1] == '\n') text[len - 1] = '\0';
    char answer[FMB_SERVE_MAX_ANSWER + 128];
    const size_t alen = fmb_serve_answer(answer, seq, rc, text ? text : "", msg);
    free(text);
    if (write_all(FMB_SERVE_ANSWER_FD, answer, alen) != 0) break; /* the sweep is gone */
  }
  fclose(in);
  return 0;
}
