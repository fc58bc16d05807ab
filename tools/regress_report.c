/* regress_report.c — what `flexmbd regress` tells: one table row per scene on stdout, the reason
 * of each failure, and (--junit FILE) the same as JUnit XML for a CI system. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "regress.h"

int regress_write_junit(const char* path, RegressJob* const* jobs, int n) {
  char err[300] = "";
  fmbSafeFile* sf = fmb_cli_safe_open(path, err, sizeof err);
  FILE* f = fmb_safe_stream(sf);
  if (!f) {
    fprintf(stderr, "flexmbd regress: cannot write %s: %s\n", path, err[0] ? err : strerror(errno));
    fmb_safe_close(sf, 0);
    return -1;
  }
  int nfail = 0, nerr = 0;
  double total = 0.0;
  for (int i = 0; i < n; ++i) {
    nfail += jobs[i]->failed && !jobs[i]->bad_input;
    nerr += jobs[i]->bad_input;
    total += jobs[i]->run.cpu_s;
  }
  fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
  fprintf(
      f,
      "<testsuites>\n<testsuite name=\"flexmbd regress\" tests=\"%d\" failures=\"%d\" errors=\"%d\" time=\"%.4f\">\n",
      n, nfail, nerr, total);
  for (int i = 0; i < n; ++i) {
    const RegressJob* j = jobs[i];
    fprintf(f, "  <testcase classname=\"regress\" name=\"");
    fmb_write_xml_text(f, j->scene);
    fprintf(f, "\" time=\"%.4f\"", j->run.cpu_s);
    if (!j->failed && !j->bad_input) {
      fprintf(f, "/>\n");
      continue;
    }
    fprintf(f, ">\n    <%s message=\"", j->bad_input ? "error" : "failure");
    fmb_write_xml_text(f, j->why);
    fprintf(f, "\">");
    if (j->worst[0]) {
      char detail[400];
      snprintf(detail, sizeof detail, "worst column %s: max error %.3g, tolerance %.3g, at t = %.6g", j->worst,
               j->worst_err, j->worst_tol, j->worst_t);
      fmb_write_xml_text(f, detail);
    }
    fprintf(f, "</%s>\n  </testcase>\n", j->bad_input ? "error" : "failure");
  }
  fprintf(f, "</testsuite>\n</testsuites>\n");
  if (fmb_safe_close(sf, 1) != 0) {
    fprintf(stderr, "flexmbd regress: cannot write %s: %s\n", path, strerror(errno));
    return -1;
  }
  return 0;
}

void regress_print_table(RegressJob* const* jobs, int n, const RegressOptions* o) {
  int w = 5;
  for (int i = 0; i < n; ++i) w = (int)fmax(w, (double)strlen(jobs[i]->scene));
  if (o->bless) {
    printf("%-*s  %-9s  %8s  %s\n", w, "scene", "reference", "cpu_s", "t_reached");
    for (int i = 0; i < n; ++i) {
      const RegressJob* j = jobs[i];
      printf("%-*s  %-9s  %8.3f  %.6g\n", w, j->scene, j->failed || j->bad_input ? "FAILED" : j->action, j->run.cpu_s,
             j->run.t_reached);
    }
  } else {
    printf("%-*s  %-24s  %10s  %10s  %10s  %-6s  %8s  %8s\n", w, "scene", "worst column", "max error", "tolerance",
           "t(max)", "result", "cpu_s", "ref_cpu");
    for (int i = 0; i < n; ++i) {
      const RegressJob* j = jobs[i];
      const char* res = j->bad_input ? "ERROR" : j->failed ? "FAIL" : "pass";
      if (j->worst[0])
        printf("%-*s  %-24s  %10.3g  %10.3g  %10.6g  %-6s  %8.3f  %8.3f%s\n", w, j->scene, j->worst, j->worst_err,
               j->worst_tol, j->worst_t, res, j->run.cpu_s, j->ref.cpu_s, j->warn_slow ? "  (slow)" : "");
      else
        printf("%-*s  %-24s  %10s  %10s  %10s  %-6s  %8.3f  %8.3f\n", w, j->scene, "-", "-", "-", "-", res,
               j->run.cpu_s, j->ref.cpu_s);
    }
  }
  for (int i = 0; i < n; ++i) {
    const RegressJob* j = jobs[i];
    if (j->failed || j->bad_input) printf("%s: %s: %s\n", j->bad_input ? "error" : "FAIL", j->scene, j->why);
    if (j->warn_slow)
      printf("warning: %s: %.3f s of CPU, %.1fx the reference's %.3f s (beyond --slow %.3g)\n", j->scene, j->run.cpu_s,
             j->run.cpu_s / j->ref.cpu_s, j->ref.cpu_s, o->slow);
  }
}
