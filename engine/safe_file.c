/* safe_file.c — writing a file without ever losing one (flexmbd.h, fmb_safe_*).
 *  - a regular (or not yet existing) target is written to a temporary file beside it
 *    (".NAME.XXXXXX", same directory, so same file system) that replaces it only when the writer
 *    says so (fmb_safe_close with keep): a writer that stops early leaves the target as it was;
 *  - "-" (stdout) and non-regular targets (/dev/null, a FIFO, a terminal) are written straight
 *    through and never removed;
 *  - a symbolic link is followed: the file it names is the target, the link stays; the old file's
 *    permissions are kept (a new one gets 0666 less the umask, as fopen would give).
 *  - a target that is one of the process's inputs (same device and inode, whatever the name or
 *    link that leads to it) is refused: fmb_load notes the scene and its table files, plugin
 *    loading the shared objects, a command the files it reads (fmb_safe_note_input), so no
 *    writer anywhere can replace what the run was computed from. A note lasts until the process
 *    ends (a command that loads a scene once per speed and writes at the end is still covered)
 *    or until a program undoes it (fmb_safe_forget_input).
 * The CSV writer (output.c), the VTK files, references, JUnit reports and plots all use it. */
#include <errno.h>
#include <fcntl.h>
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

/* the inputs noted so far, by device and inode; refs: how many notes (a model's, a command's) */
typedef struct {
  dev_t dev;
  ino_t ino;
  int refs;
  char* path; /* as the program named it, for messages */
  char* real; /* its absolute name when noted (realpath), to tell a stale note */
} InputFile;
static InputFile* input_file;
static int ninput_file, cap_input_file;

static InputFile* input_same_as(const struct stat* st) {
  for (int i = 0; i < ninput_file; ++i)
    if (input_file[i].dev == st->st_dev && input_file[i].ino == st->st_ino) return &input_file[i];
  return NULL;
}

static void forget_all_inputs(void) { /* at exit: valgrind counts what is still reachable */
  for (int i = 0; i < ninput_file; ++i) {
    free(input_file[i].path);
    free(input_file[i].real);
  }
  free(input_file);
  input_file = NULL;
  ninput_file = cap_input_file = 0;
}

int fmb_safe_note_input(const char* path) {
  struct stat st;
  if (!path || strcmp(path, "-") == 0 || stat(path, &st) != 0 || !S_ISREG(st.st_mode)) return -1;
  InputFile* in = input_same_as(&st);
  if (in) {
    in->refs++;
    return 0;
  }
  if (ninput_file == cap_input_file) {
    const int cap = cap_input_file ? 2 * cap_input_file : 16;
    InputFile* grown = realloc(input_file, (size_t)cap * sizeof *grown);
    if (!grown) return -1;
    if (!input_file) atexit(forget_all_inputs);
    input_file = grown;
    cap_input_file = cap;
  }
  char* copy = strdup(path);
  char* real = realpath(path, NULL);
  if (!copy || !real) {
    free(copy);
    free(real);
    return -1;
  }
  input_file[ninput_file++] = (InputFile){st.st_dev, st.st_ino, 1, copy, real};
  return 0;
}

void fmb_safe_forget_input(const char* path) {
  if (!path) return;
  struct stat st;
  InputFile* in = stat(path, &st) == 0 ? input_same_as(&st) : NULL;
  for (int i = 0; !in && i < ninput_file; ++i) /* a file renamed or replaced since: by its name */
    if (strcmp(input_file[i].path, path) == 0) in = &input_file[i];
  if (!in || --in->refs > 0) return;
  free(in->path);
  free(in->real);
  *in = input_file[--ninput_file];
  if (ninput_file == 0) { /* nothing noted: nothing held (valgrind counts what is still reachable) */
    free(input_file);
    input_file = NULL;
    cap_input_file = 0;
  }
}

const char* fmb_safe_input_at(const char* path) {
  struct stat st, noted;
  if (!path || strcmp(path, "-") == 0 || stat(path, &st) != 0 || !S_ISREG(st.st_mode)) return NULL;
  const InputFile* in = input_same_as(&st);
  /* a note whose own name no longer leads to that file is stale: the input was deleted or
     replaced since, and its inode may now belong to an unrelated file */
  if (!in || stat(in->real, &noted) != 0 || noted.st_dev != st.st_dev || noted.st_ino != st.st_ino) return NULL;
  return in->path;
}

static fmbSafeFile* fail(fmbSafeFile* f, char* err, size_t errlen, const char* path, const char* what) {
  (void)path;
  if (err && errlen) snprintf(err, errlen, "%s", what);
  fmb_safe_close(f, 0);
  return NULL;
}

fmbSafeFile* fmb_safe_open(const char* path, char* err, size_t errlen) {
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
  const char* input = exists ? fmb_safe_input_at(path) : NULL;
  if (input) {
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
