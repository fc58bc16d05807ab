/* diag.c — diagnostics: an fmbDiag filled (the first error wins), and where a scene's node is
 * for a message: file:line:column (libyaml marks are 0-based; we print 1-based) or the `--set`
 * override that made it, shown on one line. Apart from yaml_get.c (the accessors and the YAML
 * composer) because every layer sets diagnostics and only the parser walks YAML. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"

void fmb_diag_set(fmbDiag* d, int code, const char* file, int line, int col, const char* fmt, ...) {
  if (!d || d->code) return; /* the first error wins */
  d->code = code;
  snprintf(d->file, sizeof d->file, "%s", file ? file : "");
  d->line = line;
  d->col = col;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(d->msg, sizeof d->msg, fmt, ap);
  va_end(ap);
}

const char* fmbp_shown_override(const char* text, char buf[FMB_OVERRIDE_SHOWN + 32]) {
  size_t used = 0, i = 0;
  const size_t len = strlen(text);
  for (; text[i] && used < FMB_OVERRIDE_SHOWN - 20; ++i) {
    const unsigned char ch = (unsigned char)text[i];
    if (ch == '\n' || ch == '\t')
      used += (size_t)snprintf(buf + used, 8, "\\%c", ch == '\n' ? 'n' : 't');
    else if (ch < 0x20 || ch == 0x7f)
      used += (size_t)snprintf(buf + used, 8, "\\x%02x", ch);
    else
      buf[used++] = (char)ch;
  }
  if (text[i] && len > FMB_OVERRIDE_SHOWN) {
    snprintf(buf + used, FMB_OVERRIDE_SHOWN + 32 - used, "...(%zu characters)", len);
    return buf;
  }
  for (; text[i] && used < FMB_OVERRIDE_SHOWN + 24; ++i) {
    const unsigned char ch = (unsigned char)text[i];
    if (ch < 0x20 || ch == 0x7f)
      used += (size_t)snprintf(buf + used, 8, "\\x%02x", ch);
    else
      buf[used++] = (char)ch;
  }
  buf[used] = '\0';
  return buf;
}

/* where `node` is: file:line:column, or the override that made it */
static void diag_at(fmbParser* p, fmbNode node, fmbDiag* d, const char* msg) {
  /* the node itself (libyaml's lookup, not yaml_get.c's, which calls into this file) */
  yaml_node_t* nd = node > 0 ? yaml_document_get_node(&p->doc, node) : NULL;
  int ov = (node > 0 && p->override_of && node <= p->nnodes_cap) ? p->override_of[node] : -1;
  char shown[FMB_OVERRIDE_SHOWN + 32];
  if (ov >= 0)
    fmb_diag_set(d, FMB_EXIT_BAD_INPUT, "--set", 0, 0, "%s: %s", fmbp_shown_override(p->overrides[ov], shown), msg);
  else if (nd)
    fmb_diag_set(d, FMB_EXIT_BAD_INPUT, p->path, (int)nd->start_mark.line + 1, (int)nd->start_mark.column + 1, "%s",
                 msg);
  else
    fmb_diag_set(d, FMB_EXIT_BAD_INPUT, p->path, 0, 0, "%s", msg);
}

static int verror_at(fmbParser* p, fmbNode node, const char* fmt, va_list ap) {
  char msg[900];
  vsnprintf(msg, sizeof msg, fmt, ap);
  diag_at(p, node, p->diag, msg);
  return -1;
}

int fmb_parse_error(fmbParser* p, fmbNode node, const char* fmt, ...) {
  if (!p || !fmt) return -1;
  va_list ap;
  va_start(ap, fmt);
  verror_at(p, node, fmt, ap);
  va_end(ap);
  return -1;
}

/* a warning does not stop the load: FILE:LINE:COL: warning: ... (or the override), to the thread's
   warn handler (warn.c) */
void fmbp_warning_at(fmbParser* p, fmbNode node, const char* fmt, ...) {
  char msg[600];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  fmbDiag w;
  memset(&w, 0, sizeof w);
  diag_at(p, node, &w, msg);
  if (w.line > 0)
    fmb_warn(NULL, "%s:%d:%d: warning: %s", w.file, w.line, w.col, w.msg);
  else
    fmb_warn(NULL, "%s: warning: %s", w.file, w.msg);
}
