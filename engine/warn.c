/* warn.c — the library's one way to say something that is not an error (issue 24): a warning, a
 * note, a progress line. The library never writes to stderr itself; the host decides, as with
 * MuJoCo's mju_user_warning. A message goes to the run's own handler (fmb_data_set_warn, kept in
 * its workspace), else to the calling thread's default (fmb_set_warn), else, in a thread that set
 * none, to stderr as one line: an embedding program that does nothing still sees its warnings,
 * and one that wants silence says fmb_set_warn(NULL, NULL).
 * The default is thread-local, so two threads running two models can route their messages apart
 * without a lock. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"

static _Thread_local struct {
  fmbWarnFn fn;
  void* user;
  int set; /* 0: never set in this thread: stderr */
} thread_default;

void fmb_set_warn(fmbWarnFn fn, void* user) {
  thread_default.fn = fn;
  thread_default.user = user;
  thread_default.set = 1;
}

void fmb_warn(fmbWorkspace* w, const char* fmt, ...) {
  char message[2048];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(message, sizeof message, fmt, ap);
  va_end(ap);
  fmbWarnSink* own = w ? fmb_workspace_warn(w) : NULL;
  if (own && strncmp(message, "warning", 7) == 0) own->warnings++; /* a run's count, wherever it goes */
  if (own && own->fn)
    own->fn(own->user, message);
  else if (thread_default.set) {
    if (thread_default.fn) thread_default.fn(thread_default.user, message);
  } else {
    fprintf(stderr, "%s\n", message);
  }
}
