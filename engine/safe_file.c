/* safe_file.c — writing a file without ever losing one (flexmbd.h, fmb_safe_*).
 *  - a regular (or not yet existing) target is written to a temporary file beside it
 *    (".NAME.XXXXXX", same directory, so same file system) that replaces it only when the writer
 *    says so (fmb_safe_close with keep): a writer that stops early leaves the target as it was;
 *  - "-" (stdout) and non-regular targets (/dev/null, a FIFO, a terminal) are written straight
 *    through and never removed;
 *  - a symbolic link is followed: the file it names is the target, the link stays; the old file's
 *    permissions are kept (a new one gets 0666 less the umask, as fopen would give).
 *  - a target that is one of the inputs the writer is given (an fmbInputs: same device and inode,
 *    whatever the name or link that leads to it) is refused (fmb_safe_open_guarded): each model
 *    keeps the set of what fmb_load read (the scene, its table files, its plugins) and every
 *    writer of a run checks against it; the CLI keeps one set for the whole command (tools/cli.c:
 *    its scene, samples, references, --plugin files and every model it loaded). There is no
 *    process-wide list: two threads loading and writing share nothing here (issue 35 item 3).
 * The CSV writer (output.c), the VTK files, references, JUnit reports and plots all use it. */
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "internal.h"

struct fmbSafeFile {
  int fd;
  int through;  /* stdout or a non-regular target: written in place, never removed */
  char* target; /* the file written (symbolic links resolved) */
  char* temp;   /* the temporary file beside it, NULL when written through */
  FILE* stream; /* fmb_safe_stream's, over fd */
};

/* a set of input files, by device and inode; refs: how many notes (a model's, a command's).
   Its own lock: one set may be shared by threads (a command's, noted from its workers). */
typedef struct {
  dev_t dev;
  ino_t ino;
  int refs;
  char* path; /* as the program named it, for messages */
  char* real; /* its absolute name when noted (realpath), to tell a stale note */
} InputFile;
struct fmbInputs {
  pthread_mutex_t lock;
  InputFile* file;
  int n, cap;
};

fmbInputs* fmb_inputs_new(void) {
  fmbInputs* in = calloc(1, sizeof *in);
  if (in && pthread_mutex_init(&in->lock, NULL) != 0) {
    free(in);
    return NULL;
  }
  return in;
}

void fmb_inputs_free(fmbInputs* in) {
  if (!in) return;
  for (int i = 0; i < in->n; ++i) {
    free(in->file[i].path);
    free(in->file[i].real);
  }
  free(in->file);
  pthread_mutex_destroy(&in->lock);
  free(in);
}

static InputFile* input_same_as(const fmbInputs* in, const struct stat* st) {
  for (int i = 0; i < in->n; ++i)
    if (in->file[i].dev == st->st_dev && in->file[i].ino == st->st_ino) return &in->file[i];
  return NULL;
}

/* under in->lock */
static int note_locked(fmbInputs* in, const char* path, const struct stat* st, int refs) {
  InputFile* have = input_same_as(in, st);
  if (have) {
    have->refs += refs;
    return 0;
  }
  if (in->n == in->cap) {
    const int cap = in->cap ? 2 * in->cap : 8;
    InputFile* grown = realloc(in->file, (size_t)cap * sizeof *grown);
    if (!grown) return -1;
    in->file = grown;
    in->cap = cap;
  }
  char* copy = strdup(path);
  char* real = realpath(path, NULL);
  if (!copy || !real) {
    free(copy);
    free(real);
    return -1;
  }
  in->file[in->n++] = (InputFile){st->st_dev, st->st_ino, refs, copy, real};
  return 0;
}

int fmb_inputs_note(fmbInputs* in, const char* path) {
  struct stat st;
  if (!in || !path || strcmp(path, "-") == 0 || stat(path, &st) != 0 || !S_ISREG(st.st_mode)) return -1;
  pthread_mutex_lock(&in->lock);
  const int rc = note_locked(in, path, &st, 1);
  pthread_mutex_unlock(&in->lock);
  return rc;
}

int fmb_inputs_add(fmbInputs* to, const fmbInputs* from) {
  if (!to || !from) return -1;
  if (to == from) return 0;
  /* from's names are copied under its lock, then noted under to's: one lock held at a time, so
     two threads adding two sets into each other cannot deadlock */
  fmbInputs* src = (fmbInputs*)from;
  pthread_mutex_lock(&src->lock);
  const int n = src->n;
  char** names = calloc((size_t)n + 1, sizeof *names);
  int rc = names ? 0 : -1;
  for (int i = 0; names && i < n; ++i)
    if (!(names[i] = strdup(src->file[i].path))) rc = -1;
  pthread_mutex_unlock(&src->lock);
  for (int i = 0; names && i < n; ++i) /* a file deleted since is no longer an input to keep */
    if (names[i] && fmb_inputs_note(to, names[i]) != 0 && access(names[i], F_OK) == 0) rc = -1;
  for (int i = 0; names && i < n; ++i) free(names[i]);
  free(names);
  return rc;
}

void fmb_inputs_forget(fmbInputs* in, const char* path) {
  if (!in || !path) return;
  struct stat st;
  pthread_mutex_lock(&in->lock);
  InputFile* have = stat(path, &st) == 0 ? input_same_as(in, &st) : NULL;
  for (int i = 0; !have && i < in->n; ++i) /* a file renamed or replaced since: by its name */
    if (strcmp(in->file[i].path, path) == 0) have = &in->file[i];
  if (have && --have->refs <= 0) {
    free(have->path);
    free(have->real);
    *have = in->file[--in->n];
  }
  pthread_mutex_unlock(&in->lock);
}

int fmb_inputs_count(const fmbInputs* in) {
  if (!in) return 0;
  fmbInputs* lk = (fmbInputs*)in;
  pthread_mutex_lock(&lk->lock);
  const int n = in->n;
  pthread_mutex_unlock(&lk->lock);
  return n;
}

int fmb_inputs_at(const fmbInputs* in, const char* path, char* name, size_t namelen) {
  struct stat st, noted;
  if (name && namelen) name[0] = '\0';
  if (!in || !path || strcmp(path, "-") == 0 || stat(path, &st) != 0 || !S_ISREG(st.st_mode)) return 0;
  fmbInputs* lk = (fmbInputs*)in;
  pthread_mutex_lock(&lk->lock);
  const InputFile* have = input_same_as(in, &st);
  /* a note whose own name no longer leads to that file is stale: the input was deleted or
     replaced since, and its inode may now belong to an unrelated file */
  const int is = have && stat(have->real, &noted) == 0 && noted.st_dev == st.st_dev && noted.st_ino == st.st_ino;
  if (is && name && namelen) snprintf(name, namelen, "%s", have->path);
  pthread_mutex_unlock(&lk->lock);
  return is;
}

static fmbSafeFile* fail(fmbSafeFile* f, char* err, size_t errlen, const char* path, const char* what) {
  (void)path;
  if (err && errlen) snprintf(err, errlen, "%s", what);
  fmb_safe_close(f, 0);
  return NULL;
}

fmbSafeFile* fmb_safe_open(const char* path, char* err, size_t errlen) {
  return fmb_safe_open_guarded(path, NULL, err, errlen);
}

fmbSafeFile* fmb_safe_open_guarded(const char* path, const fmbInputs* inputs, char* err, size_t errlen) {
  if (!path) return fail(NULL, err, errlen, path, "no file name");
  fmbSafeFile* f = calloc(1, sizeof *f);
  if (!f) return fail(NULL, err, errlen, path, "out of memory");
  f->fd = -1;
  if (strcmp(path, "-") == 0) {
    fflush(stdout);
    f->fd = STDOUT_FILENO;
    f->through = 1;
    return f;
  }
  struct stat st, lst;
  const int exists = stat(path, &st) == 0;
  if (!exists && lstat(path, &lst) == 0 && S_ISLNK(lst.st_mode))
    return fail(f, err, errlen, path, "it is a symbolic link to a file that does not exist");
  if (exists && S_ISDIR(st.st_mode)) return fail(f, err, errlen, path, strerror(EISDIR));
  if (exists && !S_ISREG(st.st_mode)) {
    /* a device or FIFO: write through, no truncation, never removed */
    f->fd = open(path, O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (f->fd < 0) return fail(f, err, errlen, path, strerror(errno));
    f->through = 1;
    f->target = strdup(path); /* never removed: only the temporary file ever is */
    return f;
  }
  char input[512];
  if (exists && fmb_inputs_at(inputs, path, input, sizeof input)) {
    if (err && errlen) snprintf(err, errlen, "it is the input '%s': refusing to overwrite it", input);
    fmb_safe_close(f, 0);
    return NULL;
  }
  if (exists && access(path, W_OK) != 0) return fail(f, err, errlen, path, strerror(errno));
  f->target = exists ? realpath(path, NULL) : strdup(path);
  if (!f->target) return fail(f, err, errlen, path, strerror(errno));
  const char* slash = strrchr(f->target, '/');
  const size_t dirlen = slash ? (size_t)(slash - f->target) + 1 : 0;
  const char* base = slash ? slash + 1 : f->target;
  const size_t n = dirlen + strlen(base) + 16;
  f->temp = malloc(n);
  if (!f->temp) return fail(f, err, errlen, path, "out of memory");
  snprintf(f->temp, n, "%.*s.%s.XXXXXX", (int)dirlen, f->target, base);
  f->fd = mkstemp(f->temp);
  if (f->fd < 0) {
    const int e = errno;
    free(f->temp);
    f->temp = NULL;
    return fail(f, err, errlen, path, strerror(e));
  }
  mode_t mode = exists ? (st.st_mode & 07777) : 0666;
  if (!exists) {
    const mode_t mask = umask(0);
    umask(mask);
    mode &= ~mask;
  }
  if (fchmod(f->fd, mode) != 0) return fail(f, err, errlen, path, strerror(errno));
  return f;
}

int fmb_safe_fd(const fmbSafeFile* f) { return f ? f->fd : -1; }
int fmb_safe_is_temporary(const fmbSafeFile* f) { return f && f->temp; }
const char* fmb_safe_write_path(const fmbSafeFile* f) { return !f ? NULL : f->temp ? f->temp : f->target; }

FILE* fmb_safe_stream(fmbSafeFile* f) {
  if (!f || f->fd < 0) return NULL;
  if (!f->stream) {
    if (f->fd == STDOUT_FILENO) return f->stream = stdout;
    f->stream = fdopen(f->fd, "w");
  }
  return f->stream;
}

int fmb_safe_close(fmbSafeFile* f, int keep) {
  if (!f) return 0;
  int rc = 0;
  if (f->stream && (fflush(f->stream) != 0 || ferror(f->stream))) rc = -1;
  if (f->temp) {
    if (keep && rc == 0 && fsync(f->fd) != 0 && errno != EINVAL) rc = -1;
    if ((f->stream ? fclose(f->stream) : close(f->fd)) != 0) rc = -1;
    if (keep && rc == 0 && rename(f->temp, f->target) != 0) rc = -1;
    const int err = errno;
    if (!keep || rc) unlink(f->temp);
    errno = err;
  } else if (f->fd > STDERR_FILENO) {
    if ((f->stream ? fclose(f->stream) : close(f->fd)) != 0) rc = -1;
  }
  free(f->temp);
  free(f->target);
  free(f);
  return rc;
}
