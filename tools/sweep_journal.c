/* sweep_journal.c — DIR/runs.csv, the plain-text truth of a sweep (docs/sweep.md, "Files").
 *
 * One line per finished run, appended with a single write(2) as the run ends: the kernel holds it
 * from then on, so a crash of the sweep (kill -9, a lost node, a wall-time limit) loses at most
 * the runs in flight. Flushing to the disk itself (fdatasync) is what only a crash of the machine
 * needs, and it costs 5.3 ms per call on this VM's ext4 (write alone: 0.6 us): done at most once
 * a second (FMB_SWEEP_SYNC_S) and at the end, never per row (two per run made the four-bar
 * sweep spend 13.5 ms per run outside its 4 ms runs). A machine crash loses at most the last
 * second of rows, whose runs the resume does again. Those were recorded in DIR/inflight.log when they started: a resume
 * re-runs them first, one at a time, and marks one `lost` after FMB_SWEEP_MAX_RETRIES starts
 * without a row. A run is known by its id (a hash of what determines its result, cmd_sweep.c),
 * not by its position, so a re-planned sweep (`--resume` with other values) reuses every run it
 * shares with the old plan. */
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "sweep.h"

const char* const fmb_sweep_stat_names[FMB_SWEEP_NSTATS] = {
    "t_reached",        "steps",      "residuals",        "jacobians", "newton_iters",
    "error_test_fails", "conv_fails", "jacobians_reused", "cpu_s"};

static const char* const metric_suffix[4] = {"max", "min", "end", "rms"};

int fmb_sweep_header(const fmbSweep* sw, char* buf, size_t len) {
  size_t n = (size_t)snprintf(buf, len, "%s", FMB_SWEEP_LEAD);
#define PUT(...)                                                       \
  do {                                                                 \
    if (n < len) n += (size_t)snprintf(buf + n, len - n, __VA_ARGS__); \
  } while (0)
  for (int k = 0; k < sw->plan.npath; ++k) PUT(",%s", sw->plan.path[k]);
  for (int k = 0; k < FMB_SWEEP_NSTATS; ++k) PUT(",%s", fmb_sweep_stat_names[k]);
  for (int k = 0; k < sw->nmetric; ++k) PUT(",%s.%s", sw->metric[k].column, metric_suffix[sw->metric[k].kind]);
  for (int k = 0; k < sw->nrefcol; ++k)
    PUT(",%s.err_max,%s.err_end", sw->ref.name[sw->refcol[k]], sw->ref.name[sw->refcol[k]]);
  PUT(",message");
#undef PUT
  return n < len ? (int)n : -1;
}

/* ---- id -> index (the first index with that id) ---------------------------------------------- */
typedef struct {
  uint64_t* key;
  long* val;
  size_t mask;
} IdMap;

static int idmap_build(IdMap* m, const uint64_t* id, long n) {
  size_t cap = 16;
  while (cap < 2 * (size_t)n) cap *= 2;
  m->key = calloc(cap, sizeof *m->key);
  m->val = malloc(cap * sizeof *m->val);
  m->mask = cap - 1;
  if (!m->key || !m->val) return -1;
  for (size_t i = 0; i < cap; ++i) m->val[i] = -1;
  for (long i = 0; i < n; ++i) {
    size_t h = (size_t)id[i] & m->mask;
    while (m->val[h] >= 0 && m->key[h] != id[i]) h = (h + 1) & m->mask;
    if (m->val[h] < 0) m->key[h] = id[i], m->val[h] = i;
  }
  return 0;
}
static long idmap_get(const IdMap* m, uint64_t id) {
  size_t h = (size_t)id & m->mask;
  while (m->val[h] >= 0) {
    if (m->key[h] == id) return m->val[h];
    h = (h + 1) & m->mask;
  }
  return -1;
}
static void idmap_free(IdMap* m) { free(m->key), free(m->val); }

static void dir_file(const fmbSweep* sw, const char* name, char* out, size_t len) {
  snprintf(out, len, "%s/%s", sw->dir, name);
}

/* field k (0-based) of a CSV line without quotes before it: its start, or NULL */
static const char* field(const char* line, int k) {
  for (; k > 0; --k) {
    line = strchr(line, ',');
    if (!line) return NULL;
    ++line;
  }
  return line;
}

/* ---- the folder is the sweep's own ---------------------------------------------------------- */

void fmb_sweep_disk_full(fmbSweep* sw, const char* what, int err) {
  if (sw->disk_full) return;
  sw->disk_full = 1;
  snprintf(sw->disk_why, sizeof sw->disk_why, "%.500s: %s", what, strerror(err));
}

/* opens path without following a link and without waiting (a FIFO never blocks), refusing
   anything but a regular file: the fd, -1 with errno (ENOENT: it does not exist), or -2 after
   saying why */
static int open_regular(const char* path, int flags) {
  const int fd = open(path, flags | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY | O_CLOEXEC, 0644);
  if (fd < 0 && errno == ELOOP) {
    fprintf(stderr, "flexmbd sweep: %s is a symbolic link: the sweep uses only files of its own there\n", path);
    return -2;
  }
  if (fd < 0) return -1;
  struct stat st;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    close(fd);
    fprintf(stderr, "flexmbd sweep: %s is not a regular file (a FIFO, device or folder): not a sweep's\n", path);
    return -2;
  }
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  return fd;
}
static int open_own(const fmbSweep* sw, const char* name, int flags) {
  char path[4200];
  dir_file(sw, name, path, sizeof path);
  return open_regular(path, flags);
}
/* a FILE* to read path (open_regular), NULL when absent; *refused when it is not a plain file */
static FILE* read_regular(const char* path, int* refused) {
  const int fd = open_regular(path, O_RDONLY);
  if (fd == -2) *refused = 1;
  FILE* f = fd >= 0 ? fdopen(fd, "r") : NULL;
  if (fd >= 0 && !f) close(fd);
  return f;
}

int fmb_sweep_lock(fmbSweep* sw) {
  char host[256] = "?", path[4200];
  gethostname(host, sizeof host - 1);
  dir_file(sw, "sweep.lock", path, sizeof path);
  const int fd = open_own(sw, "sweep.lock", O_RDWR | O_CREAT);
  if (fd == -2) return FMB_EXIT_BAD_INPUT;
  if (fd < 0) {
    fprintf(stderr, "flexmbd sweep: cannot create %s: %s\n", path, strerror(errno));
    return FMB_EXIT_BAD_INPUT;
  }
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    char who[300] = "";
    const ssize_t n = pread(fd, who, sizeof who - 1, 0);
    who[n > 0 ? n : 0] = '\0';
    who[strcspn(who, "\n")] = '\0';
    long pid = 0;
    char other[256] = "?";
    sscanf(who, "pid %ld host %255s", &pid, other);
    fprintf(stderr,
            "flexmbd sweep: %s is in use by another sweep (pid %ld on host %s, %s): wait for it to end, or give "
            "another -o DIR\n",
            sw->dir, pid, other, path);
    close(fd);
    return FMB_EXIT_BAD_INPUT;
  }
  /* free: no sweep holds it (a lock left by a sweep that died, whatever its pid, is free again) */
  char line[400];
  const int n = snprintf(line, sizeof line, "pid %ld host %s\n", (long)getpid(), host);
  if (ftruncate(fd, 0) != 0 || pwrite(fd, line, (size_t)n, 0) != n) {
    fprintf(stderr, "flexmbd sweep: cannot write %s: %s\n", path, strerror(errno));
    close(fd);
    return FMB_EXIT_BAD_INPUT;
  }
  sw->lock_fd = fd;
  return 0;
}

/* DIR/.sweep-files: "DEV INO NAME" per file a sweep made in DIR (appended) */
static int made_here(const fmbSweep* sw, const char* name, const struct stat* st) {
  const int fd = open_own(sw, ".sweep-files", O_RDONLY);
  if (fd < 0) return 0;
  FILE* f = fdopen(fd, "r");
  if (!f) return close(fd), 0;
  char line[512];
  int found = 0;
  unsigned long long dev, ino;
  char n[400];
  while (!found && fgets(line, sizeof line, f))
    found = sscanf(line, "%llu %llu %399s", &dev, &ino, n) == 3 && dev == (unsigned long long)st->st_dev &&
            ino == (unsigned long long)st->st_ino && strcmp(n, name) == 0;
  fclose(f);
  return found;
}

static void note_made_as(const fmbSweep* sw, const char* name, const struct stat* made) {
  const struct stat st = *made;
  if (made_here(sw, name, &st)) return;
  const int fd = open_own(sw, ".sweep-files", O_WRONLY | O_CREAT | O_APPEND);
  if (fd < 0) return;
  char line[512];
  const int n =
      snprintf(line, sizeof line, "%llu %llu %s\n", (unsigned long long)st.st_dev, (unsigned long long)st.st_ino, name);
  if (write(fd, line, (size_t)n) != n) fmb_sweep_disk_full((fmbSweep*)sw, ".sweep-files", errno);
  close(fd);
}
static void note_made(const fmbSweep* sw, const char* name) {
  char path[4200];
  struct stat st;
  dir_file(sw, name, path, sizeof path);
  if (lstat(path, &st) == 0) note_made_as(sw, name, &st);
}

int fmb_sweep_may_write(const fmbSweep* sw, const char* name) {
  char path[4200];
  struct stat st;
  dir_file(sw, name, path, sizeof path);
  if (lstat(path, &st) != 0) return errno == ENOENT ? 0 : -1;
  const char* why = S_ISLNK(st.st_mode)                              ? "is a symbolic link"
                    : !S_ISREG(st.st_mode)                           ? "is not a regular file"
                    : fmb_inputs_at(fmb_cli_inputs(), path, NULL, 0) ? "is an input of this sweep"
                    : !made_here(sw, name, &st)                      ? "was not made by a sweep"
                                                                     : NULL;
  if (!why) return 0;
  fprintf(stderr, "flexmbd sweep: %s %s: refusing to replace it (move it away, or give another -o DIR)\n", path, why);
  return -1;
}

fmbSafeFile* fmb_sweep_file_open(const fmbSweep* sw, const char* name) {
  if (fmb_sweep_may_write(sw, name)) return NULL;
  char path[4200], err[600];
  dir_file(sw, name, path, sizeof path);
  fmbSafeFile* f = fmb_cli_safe_open(path, err, sizeof err);
  if (!f) fprintf(stderr, "flexmbd sweep: cannot write %s: %s\n", path, err);
  return f;
}

int fmb_sweep_file_close(fmbSweep* sw, const char* name, fmbSafeFile* f, int keep) {
  if (!f) return -1;
  /* listed before the rename (it keeps the temporary's inode): a sweep killed between the two
     leaves a file it can replace again, not one it takes for someone else's */
  struct stat st;
  if (keep && fstat(fmb_safe_fd(f), &st) == 0) note_made_as(sw, name, &st);
  const int rc = fmb_safe_close(f, keep);
  if (keep && rc != 0) {
    char path[4200];
    dir_file(sw, name, path, sizeof path);
    fmb_sweep_disk_full(sw, path, errno);
    fprintf(stderr, "flexmbd sweep: cannot write %s: %s\n", path, strerror(errno));
  }
  return rc;
}

/* renames DIR/name to DIR/name.N (the first free N) */
static void set_aside(const fmbSweep* sw, const char* name) {
  char from[4200], to[4300];
  dir_file(sw, name, from, sizeof from);
  for (int k = 1; k < 10000; ++k) {
    snprintf(to, sizeof to, "%s.%d", from, k);
    if (access(to, F_OK) != 0) {
      rename(from, to);
      return;
    }
  }
}

int fmb_journal_open(fmbSweep* sw, int resume, int fresh) {
  char path[4200], header[1 << 16];
  if (fmb_sweep_header(sw, header, sizeof header) < 0) {
    fprintf(stderr, "flexmbd sweep: too many columns\n");
    return FMB_EXIT_BAD_INPUT;
  }
  dir_file(sw, "runs.csv", path, sizeof path);
  sw->row_at = malloc((size_t)sw->nrun * sizeof *sw->row_at);
  sw->status = malloc((size_t)sw->nrun * sizeof *sw->status);
  sw->starts = calloc((size_t)sw->nrun, sizeof *sw->starts);
  if (!sw->row_at || !sw->status || !sw->starts) return FMB_EXIT_BAD_INPUT;
  for (long i = 0; i < sw->nrun; ++i) sw->row_at[i] = -1, sw->status[i] = -1;
  int rfd = open_own(sw, "runs.csv", O_RDONLY);
  if (rfd == -2) return FMB_EXIT_BAD_INPUT;
  struct stat rst;
  if (rfd >= 0 && fstat(rfd, &rst) == 0 && rst.st_size == 0) /* killed before its header: nothing in it */
    close(rfd), rfd = -1;
  FILE* f = rfd >= 0 ? fdopen(rfd, "r") : NULL;
  if (f) {
    char first[256] = "", head[1 << 16] = "";
    if (!fgets(first, sizeof first, f) || !fgets(head, sizeof head, f)) first[0] = '\0';
    head[strcspn(head, "\n")] = '\0';
    unsigned long long old = 0;
    const int has_plan = sscanf(first, "# flexmbd sweep journal: plan=%llx", &old) == 1;
    const int same_plan = has_plan && old == sw->digest;
    if (fresh) {
      fclose(f);
      f = NULL;
      set_aside(sw, "runs.csv");
      set_aside(sw, "inflight.log");
    } else if (!has_plan) {
      fclose(f);
      fprintf(stderr, "flexmbd sweep: %s is not a sweep journal; give another -o DIR, or --fresh to set it aside\n",
              path);
      return FMB_EXIT_BAD_INPUT;
    } else if (!same_plan && !resume) {
      fclose(f);
      fprintf(stderr,
              "flexmbd sweep: %s holds a journal of another plan; --resume reuses its runs that this plan shares, "
              "--fresh sets it aside\n",
              sw->dir);
      return FMB_EXIT_BAD_INPUT;
    } else if (strcmp(head, header) != 0) {
      fclose(f);
      fprintf(stderr,
              "flexmbd sweep: %s has other columns (swept paths, --metric or --reference differ); --fresh sets it "
              "aside\n",
              path);
      return FMB_EXIT_BAD_INPUT;
    }
  }
  IdMap map;
  if (idmap_build(&map, sw->id, sw->nrun)) return FMB_EXIT_BAD_INPUT;
  const int journal_existed = f != NULL; /* a journal (its header was checked above) */
  if (f) { /* resume: the latest row of each run; a partial last line (a crash mid-write) is cut */
    long at = ftell(f), good_end = at;
    size_t cap = 1 << 16;
    char* line = malloc(cap);
    ssize_t got;
    while (line && (got = getline(&line, &cap, f)) > 0) {
      if (line[got - 1] != '\n') break;
      const char* idf = field(line, 1);
      const char* stf = field(line, 3);
      if (idf && stf) {
        long i = idmap_get(&map, strtoull(idf, NULL, 16));
        char st[32];
        size_t sl = strcspn(stf, ",");
        snprintf(st, sizeof st, "%.*s", (int)(sl < 31 ? sl : 31), stf);
        if (i >= 0) sw->row_at[i] = at, sw->status[i] = fmb_child_status_of(st);
      }
      at += got;
      good_end = at;
    }
    free(line);
    fclose(f);
    const int wfd = open_own(sw, "runs.csv", O_WRONLY);
    const int cut = wfd >= 0 ? ftruncate(wfd, good_end) : -1;
    if (wfd >= 0) close(wfd);
    if (cut != 0) {
      fprintf(stderr, "flexmbd sweep: cannot cut the partial last line of %s: %s\n", path, strerror(errno));
      idmap_free(&map);
      return FMB_EXIT_BAD_INPUT;
    }
  }
  sw->journal_fd = open_own(sw, "runs.csv", O_WRONLY | O_CREAT | O_APPEND);
  if (sw->journal_fd < 0) {
    if (sw->journal_fd == -1) fprintf(stderr, "flexmbd sweep: cannot write %s: %s\n", path, strerror(errno));
    sw->journal_fd = -1;
    idmap_free(&map);
    return FMB_EXIT_BAD_INPUT;
  }
  note_made(sw, "runs.csv");
  struct stat st;
  if (fstat(sw->journal_fd, &st) == 0 && st.st_size == 0) {
    char top[1 << 16];
    int n = snprintf(top, sizeof top, "# flexmbd sweep journal: plan=%016" PRIx64 " runs=%ld scene=%s verb=%s\n",
                     sw->digest, sw->nrun, sw->scene_given ? sw->scene_given : sw->scene, sw->verb);
    for (int k = 0; k < n - 1; ++k) /* a line break in the scene's name would end the line */
      if ((unsigned char)top[k] < 32) top[k] = '?';
    n += snprintf(top + n, sizeof top - (size_t)n, "%s\n", header);
    if (n <= 0 || write(sw->journal_fd, top, (size_t)n) != n) {
      fprintf(stderr, "flexmbd sweep: cannot write %s: %s\n", path, strerror(errno));
      return FMB_EXIT_SOLVER;
    }
  }
  /* dispatches of runs without a row: the runs in flight when the sweep last stopped */
  dir_file(sw, "inflight.log", path, sizeof path);
  struct stat ist;
  if (!journal_existed && lstat(path, &ist) == 0 && !made_here(sw, "inflight.log", &ist)) {
    /* an inflight.log beside no journal: not the sweep's (someone's file, or a planted one) */
    fprintf(stderr, "flexmbd sweep: %s was not made by a sweep: refusing to append to it (move it away)\n", path);
    idmap_free(&map);
    return FMB_EXIT_BAD_INPUT;
  }
  rfd = open_own(sw, "inflight.log", O_RDONLY);
  if (rfd == -2) return idmap_free(&map), FMB_EXIT_BAD_INPUT;
  f = rfd >= 0 ? fdopen(rfd, "r") : NULL;
  if (f) {
    char line[64];
    while (fgets(line, sizeof line, f)) { /* "~ID": a start taken back (the sweep was interrupted) */
      long i = idmap_get(&map, strtoull(line + (line[0] == '~'), NULL, 16));
      if (i >= 0) sw->starts[i] += line[0] == '~' ? -1 : 1;
    }
    fclose(f);
  }
  idmap_free(&map);
  sw->inflight_fd = open_own(sw, "inflight.log", O_WRONLY | O_CREAT | O_APPEND);
  if (sw->inflight_fd < 0) {
    if (sw->inflight_fd == -1) fprintf(stderr, "flexmbd sweep: cannot write %s: %s\n", path, strerror(errno));
    sw->inflight_fd = -1;
    return FMB_EXIT_BAD_INPUT;
  }
  note_made(sw, "inflight.log");
  return 0;
}

static int write_all(int fd, const char* s, size_t n) {
  while (n > 0) {
    ssize_t w = write(fd, s, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return -1;
    s += w, n -= (size_t)w;
  }
  return 0;
}

int fmb_journal_append(fmbSweep* sw, long index, const char* row) {
  const char* stf = field(row, 3);
  char st[32] = "";
  if (stf) snprintf(st, sizeof st, "%.*s", (int)strcspn(stf, ","), stf);
  if (strcmp(st, FMB_SWEEP_CUT) == 0) { /* cut short by a full disk: no row, a resume does it again */
    fmb_sweep_disk_full(sw, "a run's own files", ENOSPC);
    return 1;
  }
  if (sw->disk_full) return 1; /* the rows after a refused one would stand for runs it lost */
  const long at = (long)lseek(sw->journal_fd, 0, SEEK_END);
  if (write_all(sw->journal_fd, row, strlen(row))) {
    char path[4200];
    dir_file(sw, "runs.csv", path, sizeof path);
    fmb_sweep_disk_full(sw, path, errno);
    if (at >= 0 && ftruncate(sw->journal_fd, at) != 0) { /* a partial row: a resume cuts it */
    }
    return 1;
  }
  const double now = fmb_pool_now();
  if (now - sw->last_sync >= FMB_SWEEP_SYNC_S) {
    fdatasync(sw->journal_fd);
    fdatasync(sw->inflight_fd);
    sw->last_sync = now;
  }
  const long first = sw->first[index];
  sw->row_at[first] = at;
  sw->status[first] = fmb_child_status_of(st);
  return 0;
}

void fmb_journal_started(fmbSweep* sw, long index) {
  char line[32];
  int n = snprintf(line, sizeof line, "%016" PRIx64 "\n", sw->id[index]);
  if (write_all(sw->inflight_fd, line, (size_t)n)) /* synced with the journal (fmb_journal_append) */
    fmb_sweep_disk_full(sw, "inflight.log", errno);
  ++sw->starts[sw->first[index]];
}

void fmb_journal_cancelled(fmbSweep* sw, long index) {
  char line[32];
  int n = snprintf(line, sizeof line, "~%016" PRIx64 "\n", sw->id[index]);
  write_all(sw->inflight_fd, line, (size_t)n);
  --sw->starts[sw->first[index]];
}

void fmb_journal_close(fmbSweep* sw) {
  if (sw->journal_fd > 0 && (fdatasync(sw->journal_fd) != 0 || close(sw->journal_fd) != 0))
    fmb_sweep_disk_full(sw, "runs.csv", errno);
  if (sw->inflight_fd > 0) fdatasync(sw->inflight_fd), close(sw->inflight_fd);
  sw->journal_fd = sw->inflight_fd = -1;
}

int fmb_journal_write_plan(fmbSweep* sw) {
  fmbSafeFile* sf = fmb_sweep_file_open(sw, "plan.csv");
  FILE* f = sf ? fmb_safe_stream(sf) : NULL;
  if (!f) return fmb_sweep_file_close(sw, "plan.csv", sf, 0), -1;
  fprintf(f, "index,run_id");
  for (int k = 0; k < sw->plan.npath; ++k) fprintf(f, ",%s", sw->plan.path[k]);
  fputc('\n', f);
  for (long i = 0; i < sw->nrun; ++i) {
    fprintf(f, "%ld,%016" PRIx64, i, sw->id[i]);
    for (int k = 0; k < sw->plan.npath; ++k) fprintf(f, ",%s", fmb_plan_value(&sw->plan, i, k));
    fputc('\n', f);
  }
  return fmb_sweep_file_close(sw, "plan.csv", sf, 1);
}

int fmb_journal_write_table(fmbSweep* sw) {
  char header[1 << 16];
  const int rfd = open_own(sw, "runs.csv", O_RDONLY);
  FILE* in = rfd >= 0 ? fdopen(rfd, "r") : NULL;
  if (!in) return -1;
  fmbSafeFile* sf = fmb_sweep_file_open(sw, "table.csv");
  FILE* f = sf ? fmb_safe_stream(sf) : NULL;
  if (!f || fmb_sweep_header(sw, header, sizeof header) < 0) {
    fclose(in);
    fmb_sweep_file_close(sw, "table.csv", sf, 0);
    return -1;
  }
  fprintf(f, "%s\n", header);
  size_t cap = 1 << 16;
  char* line = malloc(cap);
  for (long i = 0; line && i < sw->nrun; ++i) {
    const long at = sw->row_at[sw->first[i]];
    if (at < 0) continue;
    if (fseek(in, at, SEEK_SET) != 0 || getline(&line, &cap, in) <= 0) continue;
    const char* rest = strchr(line, ',');
    if (rest) fprintf(f, "%ld%s", i, rest);
  }
  free(line);
  fclose(in);
  return fmb_sweep_file_close(sw, "table.csv", sf, 1);
}

int fmb_journal_status(const char* dir) {
  char path[4200];
  int refused = 0;
  snprintf(path, sizeof path, "%s/plan.csv", dir);
  FILE* f = read_regular(path, &refused);
  if (refused) return FMB_EXIT_BAD_INPUT;
  if (!f) {
    fprintf(stderr, "flexmbd sweep --status: %s: no plan.csv (not a sweep folder?): %s\n", dir, strerror(errno));
    return FMB_EXIT_BAD_INPUT;
  }
  size_t cap = 1 << 16;
  char* line = malloc(cap);
  long n = 0, cap_ids = 1024;
  uint64_t* ids = malloc((size_t)cap_ids * sizeof *ids);
  ssize_t got;
  if (line && getline(&line, &cap, f) > 0)
    while (ids && (got = getline(&line, &cap, f)) > 0) {
      const char* idf = field(line, 1);
      if (!idf) continue;
      if (n == cap_ids) {
        uint64_t* g = realloc(ids, (size_t)(cap_ids *= 2) * sizeof *ids);
        if (!g) break;
        ids = g;
      }
      ids[n++] = strtoull(idf, NULL, 16);
    }
  fclose(f);
  IdMap map;
  int* st = calloc((size_t)n + 1, sizeof *st);
  int* started = calloc((size_t)n + 1, sizeof *started);
  if (!ids || !st || !started || idmap_build(&map, ids, n)) {
    free(line), free(ids), free(st), free(started);
    return FMB_EXIT_BAD_INPUT;
  }
  for (long i = 0; i < n; ++i) st[i] = -1;
  snprintf(path, sizeof path, "%s/runs.csv", dir);
  long rows = 0;
  if ((f = read_regular(path, &refused))) {
    while ((got = getline(&line, &cap, f)) > 0) {
      if (line[0] == '#' || line[got - 1] != '\n') continue;
      const char *idf = field(line, 1), *stf = field(line, 3);
      if (!idf || !stf || !(line[0] >= '0' && line[0] <= '9')) continue;
      long i = idmap_get(&map, strtoull(idf, NULL, 16));
      char s[32];
      snprintf(s, sizeof s, "%.*s", (int)strcspn(stf, ","), stf);
      if (i >= 0) st[i] = fmb_child_status_of(s);
      ++rows;
    }
    fclose(f);
  }
  snprintf(path, sizeof path, "%s/inflight.log", dir);
  if ((f = read_regular(path, &refused))) {
    while (getline(&line, &cap, f) > 0) {
      long i = idmap_get(&map, strtoull(line + (line[0] == '~'), NULL, 16));
      if (i >= 0) started[i] += line[0] == '~' ? -1 : 1;
    }
    fclose(f);
  }
  if (refused) {
    idmap_free(&map);
    free(line), free(ids), free(st), free(started);
    return FMB_EXIT_BAD_INPUT;
  }
  long count[FMB_CHILD_NSTATUS] = {0}, done = 0, unique = 0, inflight = 0;
  for (long i = 0; i < n; ++i) {
    if (idmap_get(&map, ids[i]) != i) continue; /* an identical run counted once */
    ++unique;
    if (st[i] >= 0) {
      ++count[st[i]];
      ++done;
    } else if (started[i] > 0) {
      ++inflight;
    }
  }
  printf("sweep %s: %ld planned (%ld distinct), %ld with a row, %ld to do (%ld were in flight when it stopped); "
         "%ld rows in runs.csv\n",
         dir, n, unique, done, unique - done, inflight, rows);
  for (int s = 0; s < FMB_CHILD_NSTATUS; ++s)
    if (count[s]) printf("  %-15s %ld\n", fmb_child_status_name((fmbChildStatus)s), count[s]);
  idmap_free(&map);
  free(line), free(ids), free(st), free(started);
  return 0;
}
