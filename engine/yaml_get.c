/* yaml_get.c — the one YAML accessor layer.
 *
 * The scene is loaded into a libyaml document; `--set PATH=VALUE` overrides edit that tree before
 * anything is parsed, so an override is validated exactly like the file. Every accessor marks the
 * keys it looks up, so that after an item is parsed any key nobody asked for is reported as
 * unknown, together with the keys that were expected. Errors carry the node's file:line:column
 * (libyaml marks are 0-based; we print 1-based) or, for nodes made by an override, its text. */
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "internal.h"

/* a scene is a few kilobytes; 64 MB is far beyond any mechanism the engine can integrate and
   bounds what libyaml is asked to hold (its document takes ~20x the text) */
#define FMB_SCENE_BYTES_MAX (64 * 1024 * 1024)

yaml_node_t* fmbp_node(fmbParser* p, fmbNode n) {
  if (n <= 0) return NULL;
  return yaml_document_get_node(&p->doc, n);
}

fmbNode fmbp_root(fmbParser* p) {
  yaml_node_t* r = yaml_document_get_root_node(&p->doc);
  return r ? (int)(r - p->doc.nodes.start) + 1 : -1;
}

static int node_count(fmbParser* p) { return (int)(p->doc.nodes.top - p->doc.nodes.start); }

int fmbp_is_map(fmbParser* p, fmbNode n) {
  yaml_node_t* nd = fmbp_node(p, n);
  return nd && nd->type == YAML_MAPPING_NODE;
}
int fmbp_is_seq(fmbParser* p, fmbNode n) {
  yaml_node_t* nd = fmbp_node(p, n);
  return nd && nd->type == YAML_SEQUENCE_NODE;
}
int fmbp_seq_len(fmbParser* p, fmbNode seq) {
  yaml_node_t* nd = fmbp_node(p, seq);
  return (nd && nd->type == YAML_SEQUENCE_NODE) ? (int)(nd->data.sequence.items.top - nd->data.sequence.items.start)
                                                : 0;
}
fmbNode fmbp_seq_item(fmbParser* p, fmbNode seq, int i) {
  yaml_node_t* nd = fmbp_node(p, seq);
  return nd->data.sequence.items.start[i];
}
const char* fmbp_scalar(fmbParser* p, fmbNode n) {
  yaml_node_t* nd = fmbp_node(p, n);
  return (nd && nd->type == YAML_SCALAR_NODE) ? (const char*)nd->data.scalar.value : NULL;
}

static const char* node_kind(yaml_node_t* nd) {
  if (!nd) return "nothing";
  switch (nd->type) {
    case YAML_MAPPING_NODE: return "a mapping";
    case YAML_SEQUENCE_NODE: return "a list";
    case YAML_SCALAR_NODE:
      if (nd->data.scalar.length == 0) return "an empty value";
      return (nd->data.scalar.style == YAML_SINGLE_QUOTED_SCALAR_STYLE ||
              nd->data.scalar.style == YAML_DOUBLE_QUOTED_SCALAR_STYLE)
                 ? "a quoted string"
                 : "a scalar";
    default: return "nothing";
  }
}

/* ------------------------------------------------------------------------------------------ */
/* keys */

void fmbp_begin_item(fmbParser* p) {
  p->nlooked = 0;
  p->valid = NULL;
  p->params = NULL;
  p->expect_complete = 0;
  p->what = NULL;
}

void fmbp_expect(fmbParser* p, const char* what, const char* const* keys, const fmbParam* params, int complete) {
  p->what = what;
  p->valid = keys;
  p->params = params;
  p->expect_complete = complete;
}

static void remember_key(fmbParser* p, const char* key) {
  for (int i = 0; i < p->nlooked; ++i)
    if (strcmp(p->looked[i], key) == 0) return;
  if (p->nlooked < (int)(sizeof p->looked / sizeof p->looked[0])) p->looked[p->nlooked++] = key;
}

static fmbNode value_of(fmbParser* p, fmbNode map, const char* key) {
  yaml_node_t* nd = fmbp_node(p, map);
  if (!nd || nd->type != YAML_MAPPING_NODE) return -1;
  for (yaml_node_pair_t* pr = nd->data.mapping.pairs.start; pr < nd->data.mapping.pairs.top; ++pr) {
    yaml_node_t* k = fmbp_node(p, pr->key);
    if (k && k->type == YAML_SCALAR_NODE && strcmp((const char*)k->data.scalar.value, key) == 0) {
      if (pr->key <= p->nnodes_cap) p->known[pr->key] = 1;
      return pr->value;
    }
  }
  return -1;
}

/* the item's own key first; an item's missing key comes from the material or section it names
   (which are searched, and their key marked read, either way: a key the item overrides is not
   an unknown key of its material) */
fmbNode fmb_find_key(fmbParser* p, fmbNode map, const char* key) {
  if (!p || !key) return -1;
  remember_key(p, key);
  fmbNode v = value_of(p, map, key);
  for (int k = 0; k < 2 && map == p->item && p->item > 0; ++k) {
    const fmbNode inherited = p->inherited[k] > 0 ? value_of(p, p->inherited[k], key) : -1;
    if (v < 0) v = inherited;
  }
  return v;
}

/* The keys the current mapping may have, in one list: those looked up so far (in the order the
   loader reads them), then the declared ones (fmbp_expect: for an item, its name, type, material
   and section, scene.c's fmb_item_keys) not yet among them, then the type's params. The list that
   "expected one of" prints is the list a key is accepted from (key_expected), so neither can
   leave out what the other has. Returns the count. */
#define FMB_EXPECTED_MAX 96
static int expected_keys(const fmbParser* p, const char* out[FMB_EXPECTED_MAX]) {
  int n = 0;
  const char* const* lists[2] = {p->looked, p->valid};
  const int counts[2] = {p->nlooked, 1 << 20};
  for (int l = 0; l < 3; ++l)
    for (int i = 0; n < FMB_EXPECTED_MAX; ++i) {
      const char* k = l < 2 ? (lists[l] && i < counts[l] ? lists[l][i] : NULL) : (p->params ? p->params[i].key : NULL);
      if (!k) break;
      int dup = 0;
      for (int j = 0; j < n && !dup; ++j) dup = strcmp(out[j], k) == 0;
      if (!dup) out[n++] = k;
    }
  return n;
}

/* optimal string alignment distance (Levenshtein with adjacent transpositions: lenght -> length
   is 1), bounded: keys are short, longer words just count as far */
static int key_distance(const char* a, const char* b) {
  enum { W = 40 };
  const int la = (int)strlen(a), lb = (int)strlen(b);
  if (la >= W || lb >= W) return W;
  int d[W + 1][W + 1];
  for (int i = 0; i <= la; ++i) d[i][0] = i;
  for (int j = 0; j <= lb; ++j) d[0][j] = j;
  for (int i = 1; i <= la; ++i)
    for (int j = 1; j <= lb; ++j) {
      const int cost = a[i - 1] != b[j - 1];
      int v = d[i - 1][j] + 1;
      if (d[i][j - 1] + 1 < v) v = d[i][j - 1] + 1;
      if (d[i - 1][j - 1] + cost < v) v = d[i - 1][j - 1] + cost;
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] && d[i - 2][j - 2] + 1 < v)
        v = d[i - 2][j - 2] + 1;
      d[i][j] = v;
    }
  return d[la][lb];
}

/* a typo: at most 1 edit in a short word, 2 from 5 letters on (t_ned, ramp_tme, lenght, omega) */
static int is_typo_of(const char* typed, const char* key) {
  const int d = key_distance(typed, key), len = (int)strlen(key);
  return d > 0 && d <= (len >= 5 ? 2 : 1);
}

const char* fmb_nearest_word(const char* typed, const char* const* words, int n) {
  const char* nearest = NULL;
  int best = 1 << 20;
  for (int i = 0; typed && words && i < n; ++i) {
    if (!words[i]) continue;
    const int d = key_distance(typed, words[i]);
    if (is_typo_of(typed, words[i]) && d < best) best = d, nearest = words[i];
  }
  return nearest;
}

/* the unknown-key message, with the nearest expected key when it is a typo of it */
static int unknown_key_error(fmbParser* p, fmbNode key, const char* k, const char* what) {
  const char* exp[FMB_EXPECTED_MAX];
  const int n = expected_keys(p, exp);
  char expected[900] = "";
  size_t used = 0;
  for (int i = 0; i < n; ++i)
    if (used + 40 < sizeof expected)
      used += (size_t)snprintf(expected + used, sizeof expected - used, "%s%s", i ? ", " : "", exp[i]);
  const char* nearest = fmb_nearest_word(k, exp, n);
  if (nearest)
    return fmb_parse_error(p, key, "unknown key '%s' in %s: did you mean '%s'? (expected one of: %s)", k, what, nearest,
                           expected);
  return fmb_parse_error(p, key, "unknown key '%s' in %s (expected one of: %s)", k, what, expected);
}

/* whether `k` may stand in the current mapping: read already, or declared (fmbp_expect) */
static int key_expected(const fmbParser* p, const char* k) {
  const char* exp[FMB_EXPECTED_MAX];
  const int n = expected_keys(p, exp);
  for (int i = 0; i < n; ++i)
    if (strcmp(exp[i], k) == 0) return 1;
  return 0;
}

int fmbp_check_unknown(fmbParser* p, fmbNode map, const char* what) {
  yaml_node_t* nd = fmbp_node(p, map);
  if (!nd || nd->type != YAML_MAPPING_NODE) return 0;
  for (yaml_node_pair_t* pr = nd->data.mapping.pairs.start; pr < nd->data.mapping.pairs.top; ++pr) {
    if (pr->key <= p->nnodes_cap && p->known[pr->key]) continue;
    const char* k = fmbp_scalar(p, pr->key);
    if (!k) return fmb_parse_error(p, pr->key, "keys must be plain words in %s", what);
    if (p->expect_complete && key_expected(p, k)) { /* a key of the type that these settings do not read */
      char read[600] = "";
      for (int i = 0, used = 0; i < p->nlooked && used + 40 < (int)sizeof read; ++i)
        used += snprintf(read + used, sizeof read - used, "%s%s", i ? ", " : "", p->looked[i]);
      return fmb_parse_error(p, pr->key,
                             "key '%s' does not apply to %s as written: it is read only with other "
                             "settings (keys read here: %s)",
                             k, what, read);
    }
    return unknown_key_error(p, pr->key, k, what);
  }
  return 0;
}

/* A required key is missing. A key beside it that the mapping may not have is reported first:
   it is most often the required key misspelt (`lenght:`), and "missing 'length'" at the item
   would name the consequence, not the mistake. With the mapping's keys declared (fmbp_expect)
   any unknown key counts, the nearest to the missing one first; without, only a typo of it. */
static int missing_key(fmbParser* p, fmbNode map, const char* key, const char* what) {
  yaml_node_t* nd = fmbp_node(p, map);
  fmbNode culprit = -1;
  const char* ck = NULL;
  int best = 1 << 20;
  const int declared = p->expect_complete;
  for (yaml_node_pair_t* pr = nd && nd->type == YAML_MAPPING_NODE ? nd->data.mapping.pairs.start : NULL;
       pr && pr < nd->data.mapping.pairs.top; ++pr) {
    if (pr->key <= p->nnodes_cap && p->known[pr->key]) continue;
    const char* k = fmbp_scalar(p, pr->key);
    if (!k || key_expected(p, k)) continue;
    const int d = key_distance(k, key);
    if ((declared || is_typo_of(k, key)) && d < best) best = d, culprit = pr->key, ck = k;
  }
  if (culprit >= 0) {
    char where[300];
    snprintf(where, sizeof where, "%s, which lacks the required '%s'", p->what ? p->what : "this mapping", key);
    return unknown_key_error(p, culprit, ck, where);
  }
  return fmb_parse_error(p, map, "missing required key '%s' (%s)", key, what);
}

/* FNV-1a: the duplicate-key check's hash */
static unsigned long hash_key(const char* s) {
  unsigned long h = 2166136261u;
  for (; *s; ++s) h = (h ^ (unsigned char)*s) * 16777619u;
  return h;
}

/* every mapping in the document: no duplicate keys, keys are scalars. Linear in the number of
   keys: each mapping's keys go into an open-addressing hash set (size a power of two at least
   twice the keys), so a mapping of 100,000 keys costs ~100,000 string comparisons, not 5e9. */
static int check_duplicates(fmbParser* p) {
  int n = node_count(p);
  size_t cap = 0;
  yaml_node_pair_t** slot = NULL;
  int rc = 0;
  for (int id = 1; id <= n && !rc; ++id) {
    yaml_node_t* nd = fmbp_node(p, id);
    if (nd->type != YAML_MAPPING_NODE) continue;
    const size_t npairs = (size_t)(nd->data.mapping.pairs.top - nd->data.mapping.pairs.start);
    size_t want = 16;
    while (want < 2 * npairs) want *= 2;
    if (want > cap) {
      free(slot);
      cap = want;
      slot = malloc(cap * sizeof *slot);
      if (!slot) return fmb_parse_error(p, id, "out of memory checking for duplicate keys");
    }
    memset(slot, 0, want * sizeof *slot);
    for (yaml_node_pair_t* a = nd->data.mapping.pairs.start; a < nd->data.mapping.pairs.top; ++a) {
      const char* ka = fmbp_scalar(p, a->key);
      if (!ka) {
        rc = fmb_parse_error(p, a->key, "a key must be a plain word, found %s", node_kind(fmbp_node(p, a->key)));
        break;
      }
      size_t h = hash_key(ka) & (want - 1);
      for (; slot[h]; h = (h + 1) & (want - 1)) {
        p->key_compares++;
        if (strcmp(fmbp_scalar(p, slot[h]->key), ka) == 0) break;
      }
      if (slot[h]) {
        yaml_node_t* first = fmbp_node(p, slot[h]->key);
        rc = fmb_parse_error(p, a->key, "duplicate key '%s' (first given at line %d)", ka,
                             (int)first->start_mark.line + 1);
        break;
      }
      slot[h] = a;
    }
  }
  free(slot);
  return rc;
}

/* ------------------------------------------------------------------------------------------ */
/* typed values */

static int parse_number(const char* s, double* out) {
  if (!s || !*s) return -1;
  /* YAML's .nan/.inf spellings (and C's nan/inf) are numbers, just not usable ones */
  const char* u = (*s == '+' || *s == '-') ? s + 1 : s;
  if (*u == '.') ++u;
  if (strcasecmp(u, "nan") == 0 || strcasecmp(u, "inf") == 0 || strcasecmp(u, "infinity") == 0) return -2;
  for (const char* c = s; *c; ++c)
    if (!(isdigit((unsigned char)*c) || *c == '.' || *c == '-' || *c == '+' || *c == 'e' || *c == 'E')) return -1;
  errno = 0;
  char* end = NULL;
  double v = strtod(s, &end);
  if (end == s || *end != '\0') return -1;
  if (!isfinite(v)) return -2;
  *out = v;
  return 0;
}

static int number_at(fmbParser* p, fmbNode n, const char* key, unsigned flags, double* out) {
  yaml_node_t* nd = fmbp_node(p, n);
  if (!nd || nd->type != YAML_SCALAR_NODE || nd->data.scalar.style == YAML_SINGLE_QUOTED_SCALAR_STYLE ||
      nd->data.scalar.style == YAML_DOUBLE_QUOTED_SCALAR_STYLE)
    return fmb_parse_error(p, n, "expected a number for '%s', found %s", key, node_kind(nd));
  const char* s = (const char*)nd->data.scalar.value;
  double v = 0;
  int rc = parse_number(s, &v);
  if (rc == -2) return fmb_parse_error(p, n, "expected a finite number for '%s', got '%s'", key, s);
  if (rc) return fmb_parse_error(p, n, "expected a number for '%s', got '%s'", key, s);
  if ((flags & FMB_POSITIVE) && !(v > 0))
    return fmb_parse_error(p, n, "expected a positive number for '%s', got %s", key, s);
  if ((flags & FMB_NONNEGATIVE) && !(v >= 0))
    return fmb_parse_error(p, n, "expected a non-negative number for '%s', got %s", key, s);
  *out = v;
  return 0;
}

static int absent(fmbParser* p, fmbNode map, const char* key, unsigned flags, const char* what) {
  if (flags & FMB_REQUIRED) return missing_key(p, map, key, what);
  return 0;
}

/* Values far outside what their unit means for any real material or part: most often a number
   written in another unit (Young's modulus in GPa, a density in g/cm^3, a length in mm), which
   runs (or fails much later, at t = 0.11 s with a generic solver message) without a word. Each
   rule applies to a key by the SI unit its type declares (fmbParam.unit; `key` NULL = any key of
   that unit) and warns once per scene. The bounds leave every structural solid inside: moduli from
   soft rubber (~1e6 Pa) to diamond (1.2e12 Pa), densities from balsa (~100 kg/m^3) to osmium
   (22,590 kg/m^3), beams from 0.1 mm to 100 m. The density's lower bound is 100, not 1 kg/m^3:
   in g/cm^3 every metal lies between 1.7 and 22.6, so a bound of 1 would catch none of them;
   a foam or an aerogel below 100 kg/m^3 still runs, with the warning. */
static const struct {
  const char* unit;
  const char* key;
  double lo, hi;
  const char *below, *above; /* the likely mistake */
} plausibility[] = {
    {"Pa", NULL, 1e5, 1e13, "GPa or MPa given as Pa? 70 GPa is 70e9", "an exponent too large? diamond is 1.2e12 Pa"},
    {"kg/m^3", NULL, 100.0, 1e5, "g/cm^3 or t/m^3 given as kg/m^3? aluminium is 2767 kg/m^3 = 2.767 g/cm^3",
     "g/m^3 or an exponent too large? osmium, the densest element, is 22590 kg/m^3"},
    {"m", "length", 1e-4, 100.0, "km given as m?", "mm given as m? 1000 mm is 1 m"},
};

static void check_plausible(fmbParser* p, fmbNode n, const char* key, double value) {
  const fmbParam* par = NULL;
  for (int i = 0; p->params && p->params[i].key && !par; ++i)
    if (strcmp(p->params[i].key, key) == 0) par = &p->params[i];
  if (!par || !par->unit) return;
  for (unsigned r = 0; r < sizeof plausibility / sizeof plausibility[0]; ++r) {
    if (strcmp(par->unit, plausibility[r].unit) != 0 || (plausibility[r].key && strcmp(plausibility[r].key, key) != 0))
      continue;
    const int low = value<plausibility[r].lo, high = value> plausibility[r].hi;
    if ((!low && !high) || (p->plausibility_warned & (1u << r))) continue;
    p->plausibility_warned |= 1u << r;
    fmbp_warning_at(p, n, "'%s: %g' %s %g %s, outside the range of real parts and materials (%g to %g %s): %s", key,
                    value, low ? "is below" : "is above", low ? plausibility[r].lo : plausibility[r].hi, par->unit,
                    plausibility[r].lo, plausibility[r].hi, par->unit,
                    low ? plausibility[r].below : plausibility[r].above);
  }
}

int fmb_get_double(fmbParser* p, fmbNode map, const char* key, unsigned flags, double* out) {
  if (!p || !key || !out) return -1; /* a plugin bug: no parser to report it through */
  fmbNode n = fmb_find_key(p, map, key);
  if (n < 0) return absent(p, map, key, flags, "a number");
  const int rc = number_at(p, n, key, flags, out);
  if (rc == 0) check_plausible(p, n, key, *out);
  return rc;
}

/* `1.2` (radians), `1.2 rad`, `120 deg` (or without the space) */
int fmb_get_angle(fmbParser* p, fmbNode map, const char* key, unsigned flags, double* out) {
  if (!p || !key || !out) return -1;
  static const double two_pi = 6.283185307179586;
  fmbNode n = fmb_find_key(p, map, key);
  if (n < 0) return absent(p, map, key, flags, "an angle");
  yaml_node_t* nd = fmbp_node(p, n);
  const char* s = fmbp_scalar(p, n);
  if (!s || nd->data.scalar.style == YAML_SINGLE_QUOTED_SCALAR_STYLE ||
      nd->data.scalar.style == YAML_DOUBLE_QUOTED_SCALAR_STYLE)
    return fmb_parse_error(p, n, "expected an angle for '%s' (radians, or with a unit: 120 deg, 2.1 rad), found %s",
                           key, node_kind(nd));
  char num[64];
  size_t len = strcspn(s, " \tdr"); /* the number ends where the unit (deg, rad) begins */
  double scale = 1.0;
  const char* unit = s + len;
  while (*unit == ' ' || *unit == '\t') ++unit;
  if (strcmp(unit, "deg") == 0)
    scale = two_pi / 360.0;
  else if (*unit && strcmp(unit, "rad") != 0)
    len = strlen(s); /* not a unit: the whole text is reported */
  double v = 0.0;
  int rc = len < sizeof num ? 0 : -1;
  if (rc == 0) {
    memcpy(num, s, len);
    num[len] = '\0';
    rc = parse_number(num, &v);
  }
  if (rc == -2) return fmb_parse_error(p, n, "expected a finite angle for '%s', got '%s'", key, s);
  if (rc)
    return fmb_parse_error(p, n, "expected an angle for '%s' (radians, or with a unit: 120 deg, 2.1 rad), got '%s'",
                           key, s);
  if ((flags & FMB_POSITIVE) && !(v > 0))
    return fmb_parse_error(p, n, "expected a positive angle for '%s', got %s", key, s);
  if ((flags & FMB_NONNEGATIVE) && !(v >= 0))
    return fmb_parse_error(p, n, "expected a non-negative angle for '%s', got %s", key, s);
  if ((flags & FMB_POSE) && !*unit && fabs(v) > two_pi)
    fmbp_warning_at(p, n, "'%s: %s' is taken as radians (%.3g turns); write '%s deg' if degrees were meant", key, s,
                    fabs(v) / two_pi, s);
  *out = v * scale;
  return 0;
}

int fmb_get_int(fmbParser* p, fmbNode map, const char* key, unsigned flags, long lo, long hi, int* out) {
  if (!p || !key || !out) return -1; /* a plugin bug: no parser to report it through */
  fmbNode n = fmb_find_key(p, map, key);
  if (n < 0) return absent(p, map, key, flags, "a whole number");
  const char* s = fmbp_scalar(p, n);
  yaml_node_t* nd = fmbp_node(p, n);
  char* end = NULL;
  errno = 0;
  long v = s ? strtol(s, &end, 10) : 0;
  if (!s || !*s || *end != '\0' || errno == ERANGE || nd->data.scalar.style == YAML_SINGLE_QUOTED_SCALAR_STYLE ||
      nd->data.scalar.style == YAML_DOUBLE_QUOTED_SCALAR_STYLE)
    return fmb_parse_error(p, n, "expected a whole number for '%s', found %s%s%s%s", key, s ? "'" : "",
                           s ? s : node_kind(nd), s ? "'" : "", "");
  if (v < lo || v > hi)
    return fmb_parse_error(p, n, "expected a whole number from %ld to %ld for '%s', got %ld", lo, hi, key, v);
  *out = (int)v;
  return 0;
}

/* a list of n numbers (2 or 3), named `shape` in messages */
static int get_vecn(fmbParser* p, fmbNode map, const char* key, unsigned flags, int n_want, const char* shape,
                    double* out) {
  if (!p || !key || !out) return -1; /* a plugin bug: no parser to report it through */
  fmbNode n = fmb_find_key(p, map, key);
  if (n < 0) return absent(p, map, key, flags, shape);
  if (!fmbp_is_seq(p, n) || fmbp_seq_len(p, n) != n_want)
    return fmb_parse_error(p, n, "expected %s for '%s', found %s", shape, key,
                           fmbp_is_seq(p, n) ? "a list of another length" : node_kind(fmbp_node(p, n)));
  double v[4];
  for (int i = 0; i < n_want; ++i)
    if (number_at(p, fmbp_seq_item(p, n, i), key, flags & ~(unsigned)FMB_REQUIRED, &v[i])) return -1;
  for (int i = 0; i < n_want; ++i) out[i] = v[i];
  return 0;
}

int fmb_get_vec2(fmbParser* p, fmbNode map, const char* key, unsigned flags, double out[2]) {
  return get_vecn(p, map, key, flags, 2, "a list of two numbers [x, y]", out);
}

int fmb_get_vec3(fmbParser* p, fmbNode map, const char* key, unsigned flags, double out[3]) {
  return get_vecn(p, map, key, flags, 3, "a list of three numbers [x, y, z]", out);
}

int fmb_get_quat(fmbParser* p, fmbNode map, const char* key, unsigned flags, double out[4]) {
  double q[4] = {out ? out[0] : 1.0, out ? out[1] : 0.0, out ? out[2] : 0.0, out ? out[3] : 0.0};
  if (get_vecn(p, map, key, flags, 4, "a list of four numbers [w, x, y, z] (Euler parameters)", q)) return -1;
  const double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(n > 0.0) || !isfinite(n))
    return fmb_parse_error(p, fmb_find_key(p, map, key),
                           "expected Euler parameters [w, x, y, z] for '%s' that are not all zero ([1, 0, 0, 0] is "
                           "no rotation)",
                           key);
  for (int i = 0; i < 4; ++i) out[i] = q[i] / n;
  return 0;
}

int fmb_get_point3(fmbParser* p, fmbNode map, const char* key, unsigned flags, int body, double out[3]) {
  if (!p || !key || !out || !p->model || body < 0 || body >= p->model->nbody) return -1;
  if (fmb_get_vec3(p, map, key, flags, out)) return -1;
  const fmbBodyInst* b = &p->model->body[body];
  double pos[3], R[9];
  if (b->type && fmb_initial_marker3(p, body, out, pos, R))
    return fmb_parse_error(p, fmb_find_key(p, map, key),
                           "%s [%g, %g, %g] is not on body '%s' (type %s): the body cannot place it in space", key,
                           out[0], out[1], out[2], b->name, b->type->name);
  return 0;
}

int fmb_get_point(fmbParser* p, fmbNode map, const char* key, unsigned flags, int body, double out[2]) {
  if (!p || !key || !out || !p->model || body < 0 || body >= p->model->nbody) return -1;
  if (fmb_get_vec2(p, map, key, flags, out)) return -1;
  const fmbBodyInst* b = &p->model->body[body];
  double pos[2], angle;
  if (b->type && fmb_initial_marker(p, body, out, pos, &angle))
    return fmb_parse_error(p, fmb_find_key(p, map, key),
                           "%s [%g, %g] is not on body '%s' (type %s): the body cannot place it (e.g. beyond a beam's "
                           "length)",
                           key, out[0], out[1], b->name, b->type->name);
  return 0;
}

/* a table file's path is taken relative to the scene's folder */
static void sibling_path(const char* scene, const char* name, char* out, size_t len) {
  const char* slash = strrchr(scene, '/');
  if (name[0] == '/' || !slash)
    snprintf(out, len, "%s", name);
  else
    snprintf(out, len, "%.*s/%s", (int)(slash - scene), scene, name);
}

/* one row "x,y" of a table file; 1 = blank or comment, 0 = a row, -1 = not two numbers */
static int table_file_row(char* line, double xy[2]) {
  line[strcspn(line, "\r\n")] = '\0';
  char* s = line + strspn(line, " \t");
  if (!*s || *s == '#') return 1;
  char* comma = strchr(s, ',');
  if (!comma) return -1;
  *comma = '\0';
  char* a = s + strspn(s, " \t");
  char* b = comma + 1 + strspn(comma + 1, " \t");
  for (char* e = a + strlen(a); e > a && (e[-1] == ' ' || e[-1] == '\t');) *--e = '\0';
  for (char* e = b + strlen(b); e > b && (e[-1] == ' ' || e[-1] == '\t');) *--e = '\0';
  return parse_number(a, &xy[0]) || parse_number(b, &xy[1]) ? -1 : 0;
}

/* rows of an inline table (a list of [t, value] pairs) into x/y (NULL = count only) */
static int table_rows(fmbParser* p, fmbNode n, const char* key, double* x, double* y, int* count) {
  const int rows = fmbp_seq_len(p, n);
  for (int i = 0; i < rows; ++i) {
    fmbNode row = fmbp_seq_item(p, n, i);
    if (!fmbp_is_seq(p, row) || fmbp_seq_len(p, row) != 2)
      return fmb_parse_error(p, row, "expected a pair [t, value] in the table '%s'", key);
    double v[2];
    for (int k = 0; k < 2; ++k)
      if (number_at(p, fmbp_seq_item(p, row, k), key, 0, &v[k])) return -1;
    if (x) x[i] = v[0], y[i] = v[1];
  }
  *count = rows;
  return 0;
}

/* A table file is read in one pass into arrays that grow as rows come (a file that grows while it
   is read cannot outrun them), and only if it is a regular file (a FIFO or a device would be read
   without end: refused before reading) of at most TABLE_FILE_MAX bytes with rows of at most
   TABLE_LINE_MAX characters (a longer row is an error, not two rows; a longer comment is skipped). */
enum { TABLE_FILE_MAX = 64 << 20, TABLE_LINE_MAX = 4094 };
static int table_file(fmbParser* p, fmbNode n, const char* key, double** x, double** y, int* count) {
  const char* name = fmbp_scalar(p, n);
  char path[1024], line[TABLE_LINE_MAX + 2];
  sibling_path(p->path, name, path, sizeof path);
  /* O_NONBLOCK: opening a FIFO must not wait for a writer; the type is checked on the open file */
  const int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  struct stat st;
  if (fd < 0) return fmb_parse_error(p, n, "cannot read the table file '%s' for '%s': %s", path, key, strerror(errno));
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size > TABLE_FILE_MAX) {
    const int regular = fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
    close(fd);
    if (!regular)
      return fmb_parse_error(p, n,
                             "the table file '%s' for '%s' is not a regular file (a FIFO or device would be "
                             "read without end)",
                             path, key);
    return fmb_parse_error(p, n, "the table file '%s' for '%s' is larger than %d MB", path, key, TABLE_FILE_MAX >> 20);
  }
  const int flags = fcntl(fd, F_GETFL);
  if (flags >= 0) fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  FILE* f = fdopen(fd, "r");
  if (!f) {
    close(fd);
    return fmb_parse_error(p, n, "cannot read the table file '%s' for '%s': %s", path, key, strerror(errno));
  }
  int lineno = 0, header_ok = 1, rows = 0, cap = 0, rc = 0;
  long bytes = 0;
  while (!rc && fgets(line, sizeof line, f)) {
    ++lineno;
    const size_t len = strlen(line);
    bytes += (long)len;
    /* a line longer than the buffer must not become two rows (its tail read as the next line): a
       long comment is skipped whole, a long row refused */
    if (len == sizeof line - 1 && line[len - 1] != '\n') {
      const int comment = line[strspn(line, " \t")] == '#';
      int c;
      while ((c = getc(f)) != EOF && c != '\n' && bytes <= TABLE_FILE_MAX) ++bytes;
      if (comment && bytes <= TABLE_FILE_MAX) continue;
      if (!comment) {
        rc = fmb_parse_error(p, n, "table file '%s' line %d: longer than %d characters; a row is 't,value'", path,
                             lineno, TABLE_LINE_MAX);
        break;
      }
    }
    if (bytes > TABLE_FILE_MAX) { /* it grew while being read */
      rc = fmb_parse_error(p, n, "the table file '%s' for '%s' is larger than %d MB", path, key, TABLE_FILE_MAX >> 20);
      break;
    }
    double v[2];
    const int r = table_file_row(line, v);
    if (r == 1) continue;
    if (r < 0 && header_ok && rows == 0) { /* one header line of column names is allowed */
      header_ok = 0;
      continue;
    }
    if (r < 0) {
      rc = fmb_parse_error(p, n, "table file '%s' line %d: expected two numbers 't,value'", path, lineno);
      break;
    }
    if (rows == cap) {
      cap = cap ? 2 * cap : 64;
      double* gx = realloc(*x, sizeof(double) * (size_t)cap);
      if (gx) *x = gx;
      double* gy = gx ? realloc(*y, sizeof(double) * (size_t)cap) : NULL;
      if (gy) *y = gy;
      if (!gx || !gy) {
        rc = fmb_parse_error(p, n, "out of memory reading the table file '%s'", path);
        break;
      }
    }
    (*x)[rows] = v[0];
    (*y)[rows] = v[1];
    ++rows;
  }
  fclose(f);
  *count = rows;
  /* an input: no output of this model's runs may replace it (engine/safe_file.c) */
  if (!rc && p->model) fmb_inputs_note(p->model->inputs, path);
  return rc;
}

int fmb_get_table(fmbParser* p, fmbNode map, const char* key, unsigned flags, double** x, double** y, int* n) {
  if (!p || !key || !x || !y || !n) return -1; /* a plugin bug: no parser to report it through */
  fmbNode node = fmb_find_key(p, map, key);
  *x = *y = NULL;
  *n = 0;
  if (node < 0) return absent(p, map, key, flags, "a table: a list of [t, value] pairs or a CSV file name");
  if (!fmbp_is_seq(p, node) && !fmbp_scalar(p, node))
    return fmb_parse_error(p, node, "expected a list of [t, value] pairs or a CSV file name for '%s'", key);
  int rows = 0;
  if (fmbp_is_seq(p, node)) {
    if (table_rows(p, node, key, NULL, NULL, &rows)) return -1;
    if (rows >= 2) {
      *x = malloc(sizeof(double) * (size_t)rows);
      *y = malloc(sizeof(double) * (size_t)rows);
      if (!*x || !*y) return fmb_parse_error(p, node, "out of memory");
      if (table_rows(p, node, key, *x, *y, &rows)) return -1;
    }
  } else if (table_file(p, node, key, x, y, &rows)) {
    return -1;
  }
  if (rows < 2) return fmb_parse_error(p, node, "the table '%s' needs at least two rows, has %d", key, rows);
  *n = rows;
  for (int i = 1; i < rows; ++i)
    if (!((*x)[i] > (*x)[i - 1]))
      return fmb_parse_error(p, node, "the table '%s' must have strictly increasing t (row %d: %g after %g)", key,
                             i + 1, (*x)[i], (*x)[i - 1]);
  return 0;
}

int fmb_get_choice(fmbParser* p, fmbNode map, const char* key, unsigned flags, const char* const* choices, int* out) {
  if (!p || !key || !choices || !out) return -1;
  fmbNode n = fmb_find_key(p, map, key);
  char list[400] = "";
  size_t used = 0;
  for (int i = 0; choices[i] && used + 40 < sizeof list; ++i)
    used += (size_t)snprintf(list + used, sizeof list - used, "%s%s", i ? ", " : "", choices[i]);
  if (n < 0) {
    if (flags & FMB_REQUIRED) {
      char what[420];
      snprintf(what, sizeof what, "one of: %s", list);
      return missing_key(p, map, key, what);
    }
    return 0;
  }
  const char* s = fmbp_scalar(p, n);
  if (s)
    for (int i = 0; choices[i]; ++i)
      if (strcmp(s, choices[i]) == 0) {
        *out = i;
        return 0;
      }
  return fmb_parse_error(p, n, "expected one of %s for '%s', got %s%s%s", list, key, s ? "'" : "",
                         s ? s : node_kind(fmbp_node(p, n)), s ? "'" : "");
}

int fmbp_get_name(fmbParser* p, fmbNode map, const char* key, char out[FMB_NAME_MAX]) {
  fmbNode n = fmb_find_key(p, map, key);
  if (n < 0) return missing_key(p, map, key, "a name");
  const char* s = fmbp_scalar(p, n);
  if (!s || !*s) return fmb_parse_error(p, n, "expected a name for '%s', found %s", key, node_kind(fmbp_node(p, n)));
  size_t len = strlen(s);
  if (len >= FMB_NAME_MAX)
    return fmb_parse_error(p, n, "name '%.20s...' is too long (at most %d characters)", s, FMB_NAME_MAX - 1);
  for (const char* c = s; *c; ++c)
    if (!(isalnum((unsigned char)*c) || *c == '_' || *c == '-'))
      return fmb_parse_error(p, n, "name '%s' may contain only letters, digits, '_' and '-'", s);
  memcpy(out, s, len + 1);
  return 0;
}

/* a body or joint by name: index into the model's bodies (all parsed before any joint) or into
   the joints parsed so far */
static const char* body_name_at(const fmbModel* m, int i) { return m->body[i].name; }
static const char* joint_name_at(const fmbModel* m, int i) { return m->joint[i].name; }

static int get_named(fmbParser* p, fmbNode map, const char* key, unsigned flags, int joints, int* out) {
  const char* what = joints ? "joint" : "body";
  fmbNode n = fmb_find_key(p, map, key);
  if (n < 0) return absent(p, map, key, flags, joints ? "a joint name" : "a body name");
  const fmbModel* m = p->model;
  const int count = joints ? m->njoint : m->nbody;
  const char* (*name_at)(const fmbModel*, int) = joints ? joint_name_at : body_name_at;
  const char* s = fmbp_scalar(p, n);
  if (s)
    for (int i = 0; i < count; ++i)
      if (strcmp(name_at(m, i), s) == 0) {
        *out = i;
        return 0;
      }
  char list[400] = "";
  size_t used = 0;
  for (int i = 0; i < count && used + 70 < sizeof list; ++i)
    used += (size_t)snprintf(list + used, sizeof list - used, "%s%s", i ? ", " : "", name_at(m, i));
  return fmb_parse_error(
      p, n, "no %s named %s%s%s for '%s' (%s%s)", what, s ? "'" : "", s ? s : "(not a name)", s ? "'" : "", key,
      joints ? "a joint must be defined above the one that uses it; defined: " : "bodies: ", used ? list : "none");
}

int fmb_get_body(fmbParser* p, fmbNode map, const char* key, unsigned flags, int* out) {
  if (!p || !key || !out) return -1; /* a plugin bug: no parser to report it through */
  return get_named(p, map, key, flags, 0, out);
}

int fmb_get_joint(fmbParser* p, fmbNode map, const char* key, unsigned flags, int* out) {
  if (!p || !key || !out) return -1; /* a plugin bug: no parser to report it through */
  return get_named(p, map, key, flags, 1, out);
}

int fmb_joint_attachment(fmbParser* p, int joint, int k, int* body, double local[2]) {
  if (!p || !body || !local || (k != 0 && k != 1)) return -1;
  fmbModel* m = p->model;
  if (joint < 0 || joint >= m->njoint) return -1;
  const fmbJointInst* j = &m->joint[joint];
  /* only a constraining joint: a spring's ends (drawn through the same op) are no pivot to drive */
  if (!j->type->attachment || j->nrows == 0) return -1;
  return j->type->attachment(j->self, k, body, local);
}

/* the body's scene pose into q (and its velocities, its scratch after them): 2 nq + nwork doubles,
   malloc'ed (setup-time, for one call), or NULL */
static double* initial_pose(const fmbBodyInst* b) {
  const size_t n = (size_t)b->nq;
  double* q = calloc(2 * n + b->nwork + 1, sizeof(double));
  if (q) b->type->initial(b->self, q, q + n);
  return q;
}

int fmb_initial_marker(fmbParser* p, int body, const double local[2], double pos[2], double* angle) {
  if (!p || !p->model || !local || !pos || body < 0 || body >= p->model->nbody) return -1;
  const fmbBodyInst* b = &p->model->body[body];
  if (!b->type) { /* the world frame */
    pos[0] = local[0];
    pos[1] = local[1];
    if (angle) *angle = 0.0;
    return 0;
  }
  if (!b->type->marker) return -1; /* a spatial-only body */
  double* q = initial_pose(b);
  if (!q) return -1;
  const int rc = b->type->marker(b->self, q, local, pos, angle, NULL, NULL, q + 2 * (size_t)b->nq);
  free(q);
  return rc ? -1 : 0;
}

int fmb_initial_marker3(fmbParser* p, int body, const double local[3], double pos[3], double R[9]) {
  if (!p || !p->model || !local || !pos || body < 0 || body >= p->model->nbody) return -1;
  const fmbBodyInst* b = &p->model->body[body];
  if (!b->type) { /* the world frame */
    for (int i = 0; i < 3; ++i) pos[i] = local[i];
    if (R)
      for (int i = 0; i < 9; ++i) R[i] = i % 4 == 0 ? 1.0 : 0.0;
    return 0;
  }
  if (!b->marker3) return -1; /* a planar body */
  double* q = initial_pose(b);
  if (!q) return -1;
  const int rc = b->marker3(b->self, q, local, pos, R, NULL, NULL, 0, q + 2 * (size_t)b->nq);
  free(q);
  return rc ? -1 : 0;
}

/* ------------------------------------------------------------------------------------------ */
/* overrides: PATH=VALUE edits the tree; VALUE is YAML (a scalar or a flow list) */

/* an alias may point at its own enclosing node (&a [*a]) or fan out exponentially: the copy
   is a tree, so it is bounded by a node budget; 0 = failure (budget < 0 when exhausted) */
#define FMB_OVERRIDE_NODES_MAX 10000
static int copy_node(fmbParser* p, yaml_document_t* src, int id, int* budget) {
  if (--*budget < 0) return 0;
  yaml_node_t* s = yaml_document_get_node(src, id);
  int nid = 0;
  if (s->type == YAML_SCALAR_NODE) {
    nid =
        yaml_document_add_scalar(&p->doc, NULL, s->data.scalar.value, (int)s->data.scalar.length, s->data.scalar.style);
  } else if (s->type == YAML_SEQUENCE_NODE) {
    nid = yaml_document_add_sequence(&p->doc, NULL, YAML_FLOW_SEQUENCE_STYLE);
    int n = (int)(s->data.sequence.items.top - s->data.sequence.items.start);
    for (int i = 0; i < n && nid; ++i) {
      s = yaml_document_get_node(src, id);
      int c = copy_node(p, src, s->data.sequence.items.start[i], budget);
      if (!c || !yaml_document_append_sequence_item(&p->doc, nid, c)) return 0;
    }
  } else {
    nid = yaml_document_add_mapping(&p->doc, NULL, YAML_FLOW_MAPPING_STYLE);
    int n = (int)(s->data.mapping.pairs.top - s->data.mapping.pairs.start);
    for (int i = 0; i < n && nid; ++i) {
      s = yaml_document_get_node(src, id);
      yaml_node_pair_t pr = s->data.mapping.pairs.start[i];
      int k = copy_node(p, src, pr.key, budget);
      int v = copy_node(p, src, pr.value, budget);
      if (!k || !v || !yaml_document_append_mapping_pair(&p->doc, nid, k, v)) return 0;
    }
  }
  return nid;
}

static void grow_override_marks(fmbParser* p) {
  int n = node_count(p);
  if (n <= p->nnodes_cap) return;
  p->override_of = realloc(p->override_of, (size_t)(n + 1) * sizeof(int));
  for (int i = p->nnodes_cap + 1; i <= n; ++i) p->override_of[i] = -1;
  p->nnodes_cap = n;
}

static void mark_override(fmbParser* p, int first_new, int ov) {
  grow_override_marks(p);
  for (int i = first_new; i <= p->nnodes_cap; ++i) p->override_of[i] = ov;
}

static int apply_override(fmbParser* p, int ov) {
  const char* full = p->overrides[ov];
  char shown[FMB_OVERRIDE_SHOWN + 32];
  const char* text = fmbp_shown_override(full, shown);
  const char* eq = strchr(full, '=');
  if (!eq || eq == full) {
    fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, "--set", 0, 0, "%s: expected PATH=VALUE, e.g. solver.rtol=1e-8", text);
    return -1;
  }
  char path[512];
  size_t plen = (size_t)(eq - full);
  if (plen >= sizeof path) plen = sizeof path - 1;
  memcpy(path, full, plen);
  path[plen] = '\0';
  const char* value = eq + 1;

  /* parse VALUE as a YAML document of its own */
  yaml_parser_t parser;
  yaml_document_t vdoc;
  yaml_parser_initialize(&parser);
  yaml_parser_set_input_string(&parser, (const unsigned char*)value, strlen(value));
  int ok = yaml_parser_load(&parser, &vdoc);
  if (!ok || !yaml_document_get_root_node(&vdoc)) {
    fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, "--set", 0, 0, "%s: the value is not valid YAML%s%s", text,
                 parser.problem ? ": " : (ok ? " (it is empty)" : ""), parser.problem ? parser.problem : "");
    if (ok) yaml_document_delete(&vdoc);
    yaml_parser_delete(&parser);
    return -1;
  }
  /* exactly one YAML value: "1e-8\n---\n2" would otherwise set 1e-8 and drop the rest */
  yaml_document_t extra;
  int more = 0;
  if (!yaml_parser_load(&parser, &extra)) {
    more = 1;
  } else {
    more = yaml_document_get_root_node(&extra) != NULL;
    yaml_document_delete(&extra);
  }
  yaml_parser_delete(&parser);
  if (more) {
    fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, "--set", 0, 0,
                 "%s: expected one YAML value after '=', found more after it", text);
    yaml_document_delete(&vdoc);
    return -1;
  }

  if (path[0] == '.' || path[plen - 1] == '.' || strstr(path, "..")) {
    fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, "--set", 0, 0,
                 "%s: empty name in the path (write names separated by single dots, e.g. solver.rtol)", text);
    yaml_document_delete(&vdoc);
    return -1;
  }
  int node = fmbp_root(p);
  char* save = NULL;
  char* seg = strtok_r(path, ".", &save);
  int rc = 0;
  while (seg) {
    char* next = strtok_r(NULL, ".", &save);
    yaml_node_t* nd = fmbp_node(p, node);
    if (nd && nd->type == YAML_SEQUENCE_NODE) {
      /* a list of named items: bodies.NAME, joints.NAME */
      int found = -1, n = fmbp_seq_len(p, node);
      for (int i = 0; i < n && found < 0; ++i) {
        int item = fmbp_seq_item(p, node, i);
        yaml_node_t* it = fmbp_node(p, item);
        if (!it || it->type != YAML_MAPPING_NODE) continue;
        for (yaml_node_pair_t* pr = it->data.mapping.pairs.start; pr < it->data.mapping.pairs.top; ++pr) {
          const char* k = fmbp_scalar(p, pr->key);
          const char* v = fmbp_scalar(p, pr->value);
          if (k && v && strcmp(k, "name") == 0 && strcmp(v, seg) == 0) found = item;
        }
      }
      if (found < 0 || !next) {
        fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, "--set", 0, 0, "%s: %s '%s' in the scene", text,
                     found < 0 ? "no item named" : "cannot replace a whole item; name a key of", seg);
        rc = -1;
        break;
      }
      node = found;
      seg = next;
      continue;
    }
    if (!nd || nd->type != YAML_MAPPING_NODE) {
      fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, "--set", 0, 0, "%s: '%s' is not inside a mapping", text, seg);
      rc = -1;
      break;
    }
    yaml_node_pair_t* hit = NULL;
    for (yaml_node_pair_t* pr = nd->data.mapping.pairs.start; pr < nd->data.mapping.pairs.top; ++pr) {
      const char* k = fmbp_scalar(p, pr->key);
      if (k && strcmp(k, seg) == 0) hit = pr;
    }
    if (!next) {
      int first_new = node_count(p) + 1;
      int budget = FMB_OVERRIDE_NODES_MAX;
      int vid = copy_node(p, &vdoc, 1, &budget);
      if (!vid) {
        fmb_diag_set(
            p->diag, FMB_EXIT_BAD_INPUT, "--set", 0, 0, "%s: %s", text,
            budget < 0 ? "the value is too large or refers to itself (through a YAML alias)" : "out of memory");
        rc = -1;
        break;
      }
      if (hit) {
        /* the pair pointer may have moved when nodes were added: look it up again */
        nd = fmbp_node(p, node);
        for (yaml_node_pair_t* pr = nd->data.mapping.pairs.start; pr < nd->data.mapping.pairs.top; ++pr) {
          const char* k = fmbp_scalar(p, pr->key);
          if (k && strcmp(k, seg) == 0) pr->value = vid;
        }
      } else {
        int kid = yaml_document_add_scalar(&p->doc, NULL, (yaml_char_t*)seg, (int)strlen(seg), YAML_PLAIN_SCALAR_STYLE);
        if (!kid || !yaml_document_append_mapping_pair(&p->doc, node, kid, vid)) rc = -1;
      }
      mark_override(p, first_new, ov);
      break;
    }
    if (!hit) {
      fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, "--set", 0, 0, "%s: unknown path: no key '%s' in the scene", text, seg);
      rc = -1;
      break;
    }
    node = hit->value;
    seg = next;
  }
  if (!seg && rc == 0) {
    fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, "--set", 0, 0, "%s: empty path", text);
    rc = -1;
  }
  yaml_document_delete(&vdoc);
  return rc;
}

/* ------------------------------------------------------------------------------------------ */

/* libyaml's failure as file:line:column. A reader error (bad UTF-8, a NUL byte) has only a byte
   offset, so the position is counted from the file; a parser error may name where the construct
   it was reading began. */
static void syntax_error(fmbDiag* diag, const char* path, const yaml_parser_t* parser, FILE* f) {
  if (parser->error == YAML_MEMORY_ERROR) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0,
                 "the scene is too large to load: out of memory while parsing it");
    return;
  }
  const char* problem = parser->problem ? parser->problem : "unknown problem";
  if (parser->error == YAML_READER_ERROR) {
    int line = 1, col = 1, c;
    rewind(f);
    for (size_t i = 0; i < parser->problem_offset && (c = getc(f)) != EOF; ++i) {
      if (c == '\n') {
        ++line;
        col = 1;
      } else if ((c & 0xC0) != 0x80) {
        ++col;
      }
    }
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, line, col, "YAML syntax error: %s: a scene file must be UTF-8 text",
                 problem);
    return;
  }
  yaml_mark_t mk = parser->problem_mark, cm = parser->context_mark;
  /* libyaml's wording describes its own state; the usual causes get a sentence a person can act
     on, with libyaml's text after it for the rest */
  int at = -1; /* the character at the problem's line and column (columns count characters) */
  rewind(f);
  for (size_t line = 0, col = 0; (at = getc(f)) != EOF;) {
    if (line == mk.line && col == mk.column && (at & 0xC0) != 0x80) break;
    if (at == '\n')
      ++line, col = 0;
    else if ((at & 0xC0) != 0x80)
      ++col;
    if (line > mk.line) {
      at = -1;
      break;
    }
  }
  const char* plain = NULL;
  char plain_buf[300];
  if (strstr(problem, "cannot start any token") && at == '\t')
    plain = "tabs are not allowed for indentation; use spaces";
  else if (strstr(problem, "cannot start any token") && at > ' ' && at < 127) {
    snprintf(plain_buf, sizeof plain_buf, "'%c' cannot start a value; put the value in quotes (\"%c...\")", at, at);
    plain = plain_buf;
  } else if (strstr(problem, "did not find expected key") || strstr(problem, "did not find expected '-' indicator")) {
    snprintf(plain_buf, sizeof plain_buf,
             "bad indentation at line %d: the keys of one mapping, and the '- ' items of one list, must start in the "
             "same column as the others (the block began at line %d, column %d)",
             (int)mk.line + 1, (int)cm.line + 1, (int)cm.column + 1);
    plain = plain_buf;
  } else if (strstr(problem, "mapping values are not allowed")) {
    plain = "a ':' where no key may start: a line indented deeper than the key above it, or a value with ': ' in "
            "it that needs quotes";
  }
  if (plain) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, (int)mk.line + 1, (int)mk.column + 1, "%s (YAML: %s%s%s)", plain,
                 problem, parser->context ? " " : "", parser->context ? parser->context : "");
    return;
  }
  if (parser->context && (cm.line != mk.line || cm.column != mk.column))
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, (int)mk.line + 1, (int)mk.column + 1,
                 "YAML syntax error: %s %s (which began at line %d, column %d)", problem, parser->context,
                 (int)cm.line + 1, (int)cm.column + 1);
  else
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, (int)mk.line + 1, (int)mk.column + 1, "YAML syntax error: %s%s%s",
                 problem, parser->context ? " " : "", parser->context ? parser->context : "");
}

/* ------------------------------------------------------------------------------------------ */
/* the composer: YAML events into the document tree (libyaml's own loader, rewritten for three
   reasons). An alias is copied where it is used, each copied node carrying the alias's position,
   so an error inside an aliased node is reported where it is used and each use is checked on its
   own (unknown keys); a merge key `<<: *anchor` (or `<<: [*a, *b]`) adds the keys of the merged
   mappings that the mapping does not give itself (YAML 1.1 merge); the copies are bounded by a
   node budget (aliases of aliases grow exponentially: 100,000 copied nodes in all, 2,000,000 in the
   document) and the nesting by a depth limit (libyaml's
   loader recurses once per level). */
#define FMB_SCENE_NODES_MAX 2000000
#define FMB_ALIAS_NODES_MAX 100000 /* nodes copied for aliases, all uses together */
#define FMB_SCENE_DEPTH_MAX 200
#define FMB_MERGE_KEYS_MAX 1000 /* the merge is quadratic in the keys; scenes have tens */

typedef struct {
  char* name;
  int id;
} Anchor;

typedef struct {
  fmbParser* p;
  Anchor* anchors;
  int nanchors, capanchors;
  int node[FMB_SCENE_DEPTH_MAX]; /* open sequences and mappings */
  int key[FMB_SCENE_DEPTH_MAX];  /* a mapping's key waiting for its value (0 = none) */
  int depth;
  int root;
  long alias_budget; /* nodes aliases may still copy */
} Composer;

static void set_marks(yaml_document_t* doc, int id, yaml_mark_t start, yaml_mark_t end) {
  yaml_node_t* nd = yaml_document_get_node(doc, id);
  nd->start_mark = start;
  nd->end_mark = end;
}

/* a copy of node `id` and everything below it, every node marked at `at` (the alias); 0 when the
   budget of nodes is exhausted or memory is short */
static int copy_here(yaml_document_t* doc, int id, yaml_mark_t at, long* budget) {
  if (--*budget < 0) return 0;
  yaml_node_t* s = yaml_document_get_node(doc, id);
  int nid = 0;
  if (s->type == YAML_SCALAR_NODE) {
    nid = yaml_document_add_scalar(doc, NULL, s->data.scalar.value, (int)s->data.scalar.length, s->data.scalar.style);
  } else if (s->type == YAML_SEQUENCE_NODE) {
    const int n = (int)(s->data.sequence.items.top - s->data.sequence.items.start);
    nid = yaml_document_add_sequence(doc, NULL, s->data.sequence.style);
    for (int i = 0; i < n && nid; ++i) {
      s = yaml_document_get_node(doc, id); /* adding nodes may move them */
      const int c = copy_here(doc, s->data.sequence.items.start[i], at, budget);
      if (!c || !yaml_document_append_sequence_item(doc, nid, c)) return 0;
    }
  } else if (s->type == YAML_MAPPING_NODE) {
    const int n = (int)(s->data.mapping.pairs.top - s->data.mapping.pairs.start);
    nid = yaml_document_add_mapping(doc, NULL, s->data.mapping.style);
    for (int i = 0; i < n && nid; ++i) {
      s = yaml_document_get_node(doc, id);
      const yaml_node_pair_t pr = s->data.mapping.pairs.start[i];
      const int k = copy_here(doc, pr.key, at, budget);
      const int v = k ? copy_here(doc, pr.value, at, budget) : 0;
      if (!v || !yaml_document_append_mapping_pair(doc, nid, k, v)) return 0;
    }
  }
  if (nid) set_marks(doc, nid, at, at);
  return nid;
}

static int is_merge_key(yaml_document_t* doc, int id) {
  yaml_node_t* k = yaml_document_get_node(doc, id);
  return k && k->type == YAML_SCALAR_NODE && k->data.scalar.style == YAML_PLAIN_SCALAR_STYLE &&
         strcmp((const char*)k->data.scalar.value, "<<") == 0;
}

static int pairs_have_key(yaml_document_t* doc, const yaml_node_pair_t* pairs, int n, int key) {
  yaml_node_t* k = yaml_document_get_node(doc, key);
  if (!k || k->type != YAML_SCALAR_NODE) return 0;
  for (int i = 0; i < n; ++i) {
    yaml_node_t* o = yaml_document_get_node(doc, pairs[i].key);
    if (o && o->type == YAML_SCALAR_NODE &&
        strcmp((const char*)o->data.scalar.value, (const char*)k->data.scalar.value) == 0)
      return 1;
  }
  return 0;
}

/* mapping `id` is complete: replace its merge keys by the merged mappings' pairs */
static int merge_keys(Composer* c, int id) {
  yaml_document_t* doc = &c->p->doc;
  yaml_node_t* nd = yaml_document_get_node(doc, id);
  const int n = (int)(nd->data.mapping.pairs.top - nd->data.mapping.pairs.start);
  int nmerge = 0, total = 0;
  for (int i = 0; i < n; ++i) {
    const yaml_node_pair_t pr = nd->data.mapping.pairs.start[i];
    if (!is_merge_key(doc, pr.key)) {
      ++total;
      continue;
    }
    ++nmerge;
    yaml_node_t* v = yaml_document_get_node(doc, pr.value);
    const int nsrc =
        v->type == YAML_SEQUENCE_NODE ? (int)(v->data.sequence.items.top - v->data.sequence.items.start) : 1;
    for (int k = 0; k < nsrc; ++k) {
      yaml_node_t* src =
          v->type == YAML_SEQUENCE_NODE ? yaml_document_get_node(doc, v->data.sequence.items.start[k]) : v;
      if (src->type != YAML_MAPPING_NODE)
        return fmb_parse_error(c->p, v->type == YAML_SEQUENCE_NODE ? v->data.sequence.items.start[k] : pr.value,
                               "the value of a merge key '<<' must be a mapping (e.g. *anchor) or a list of mappings, "
                               "found %s",
                               node_kind(src));
      total += (int)(src->data.mapping.pairs.top - src->data.mapping.pairs.start);
    }
  }
  if (!nmerge) return 0;
  if (total > FMB_MERGE_KEYS_MAX)
    return fmb_parse_error(c->p, id, "merge keys add more than %d keys to one mapping", FMB_MERGE_KEYS_MAX);
  yaml_node_pair_t* out = malloc(((size_t)total + 1) * sizeof *out);
  if (!out) return fmb_parse_error(c->p, id, "out of memory merging keys");
  int m = 0;
  /* the mapping's own keys first: they win over merged ones */
  for (int i = 0; i < n; ++i)
    if (!is_merge_key(doc, nd->data.mapping.pairs.start[i].key)) out[m++] = nd->data.mapping.pairs.start[i];
  const int own = m;
  for (int i = 0; i < n; ++i) {
    const yaml_node_pair_t pr = nd->data.mapping.pairs.start[i];
    if (!is_merge_key(doc, pr.key)) continue;
    yaml_node_t* v = yaml_document_get_node(doc, pr.value);
    const int nsrc =
        v->type == YAML_SEQUENCE_NODE ? (int)(v->data.sequence.items.top - v->data.sequence.items.start) : 1;
    for (int k = 0; k < nsrc; ++k) {
      yaml_node_t* src =
          v->type == YAML_SEQUENCE_NODE ? yaml_document_get_node(doc, v->data.sequence.items.start[k]) : v;
      for (yaml_node_pair_t* sp = src->data.mapping.pairs.start; sp < src->data.mapping.pairs.top; ++sp)
        if (!pairs_have_key(doc, out, own, sp->key) && !pairs_have_key(doc, out + own, m - own, sp->key))
          out[m++] = *sp;
    }
  }
  free(nd->data.mapping.pairs.start); /* libyaml allocates with malloc (yaml_malloc) */
  nd->data.mapping.pairs.start = out;
  nd->data.mapping.pairs.top = out + m;
  nd->data.mapping.pairs.end = out + total + 1;
  return 0;
}

/* a finished node goes to its parent: the root, a list item, a key or a value */
static int attach(Composer* c, int id) {
  if (c->depth == 0) {
    c->root = id;
    return 0;
  }
  const int parent = c->node[c->depth - 1];
  yaml_document_t* doc = &c->p->doc;
  if (yaml_document_get_node(doc, parent)->type == YAML_SEQUENCE_NODE)
    return yaml_document_append_sequence_item(doc, parent, id) ? 0 : -1;
  if (!c->key[c->depth - 1]) {
    c->key[c->depth - 1] = id;
    return 0;
  }
  const int key = c->key[c->depth - 1];
  c->key[c->depth - 1] = 0;
  return yaml_document_append_mapping_pair(doc, parent, key, id) ? 0 : -1;
}

static int remember_anchor(Composer* c, const yaml_char_t* name, int id) {
  if (!name) return 0;
  if (c->nanchors == c->capanchors) {
    const int cap = c->capanchors ? 2 * c->capanchors : 16;
    Anchor* a = realloc(c->anchors, (size_t)cap * sizeof *a);
    if (!a) return -1;
    c->anchors = a;
    c->capanchors = cap;
  }
  c->anchors[c->nanchors].name = strdup((const char*)name);
  if (!c->anchors[c->nanchors].name) return -1;
  c->anchors[c->nanchors++].id = id;
  return 0;
}

/* one event; 1 at the end of the stream, -1 on error (diag set) */
static int compose_event(Composer* c, const yaml_event_t* ev, int* ndocs) {
  fmbParser* p = c->p;
  yaml_document_t* doc = &p->doc;
  const char* path = p->path;
  int id = 0;
  if (node_count(p) > FMB_SCENE_NODES_MAX) {
    fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, path, (int)ev->start_mark.line + 1, (int)ev->start_mark.column + 1,
                 "the scene is too large: more than %d YAML nodes (counting every use of an alias)",
                 FMB_SCENE_NODES_MAX);
    return -1;
  }
  switch (ev->type) {
    case YAML_STREAM_END_EVENT: return 1;
    case YAML_DOCUMENT_START_EVENT:
      if (++*ndocs > 1) {
        fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, path, (int)ev->start_mark.line + 1, (int)ev->start_mark.column + 1,
                     "a scene file holds one YAML document; found a second one");
        return -1;
      }
      return 0;
    case YAML_SCALAR_EVENT:
      id = yaml_document_add_scalar(doc, NULL, ev->data.scalar.value, (int)ev->data.scalar.length,
                                    ev->data.scalar.style);
      if (!id || remember_anchor(c, ev->data.scalar.anchor, id)) break;
      set_marks(doc, id, ev->start_mark, ev->end_mark);
      return attach(c, id);
    case YAML_ALIAS_EVENT: {
      int target = 0;
      for (int i = c->nanchors - 1; i >= 0 && !target; --i)
        if (strcmp(c->anchors[i].name, (const char*)ev->data.alias.anchor) == 0) target = c->anchors[i].id;
      if (!target) {
        fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, path, (int)ev->start_mark.line + 1, (int)ev->start_mark.column + 1,
                     "YAML syntax error: found undefined alias");
        return -1;
      }
      id = copy_here(doc, target, ev->start_mark, &c->alias_budget);
      if (!id && c->alias_budget < 0) {
        fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, path, (int)ev->start_mark.line + 1, (int)ev->start_mark.column + 1,
                     "the scene is too large: its aliases expand to more than %d YAML nodes", FMB_ALIAS_NODES_MAX);
        return -1;
      }
      if (!id) break;
      return attach(c, id);
    }
    case YAML_SEQUENCE_START_EVENT:
    case YAML_MAPPING_START_EVENT: {
      const int seq = ev->type == YAML_SEQUENCE_START_EVENT;
      if (c->depth == FMB_SCENE_DEPTH_MAX) {
        fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, path, (int)ev->start_mark.line + 1, (int)ev->start_mark.column + 1,
                     "the scene nests lists and mappings more than %d deep", FMB_SCENE_DEPTH_MAX);
        return -1;
      }
      id = seq ? yaml_document_add_sequence(doc, NULL, ev->data.sequence_start.style)
               : yaml_document_add_mapping(doc, NULL, ev->data.mapping_start.style);
      if (!id || remember_anchor(c, seq ? ev->data.sequence_start.anchor : ev->data.mapping_start.anchor, id)) break;
      set_marks(doc, id, ev->start_mark, ev->end_mark);
      if (attach(c, id)) break;
      c->node[c->depth] = id;
      c->key[c->depth++] = 0;
      return 0;
    }
    case YAML_SEQUENCE_END_EVENT: --c->depth; return 0;
    case YAML_MAPPING_END_EVENT: --c->depth; return merge_keys(c, c->node[c->depth]) ? -1 : 0;
    default: return 0;
  }
  fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "the scene is too large to load: out of memory");
  return -1;
}

/* the file's one document into p->doc; 0 or -1 with diag set */
static int compose(fmbParser* p, yaml_parser_t* parser, FILE* f) {
  Composer c;
  memset(&c, 0, sizeof c);
  c.p = p;
  c.alias_budget = FMB_ALIAS_NODES_MAX;
  if (!yaml_document_initialize(&p->doc, NULL, NULL, NULL, 1, 1)) {
    fmb_diag_set(p->diag, FMB_EXIT_BAD_INPUT, p->path, 0, 0, "out of memory");
    return -1;
  }
  p->have_doc = 1;
  int ndocs = 0, rc = 0;
  while (rc == 0) {
    yaml_event_t ev;
    if (!yaml_parser_parse(parser, &ev)) {
      syntax_error(p->diag, p->path, parser, f);
      rc = -1;
      break;
    }
    rc = compose_event(&c, &ev, &ndocs);
    yaml_event_delete(&ev);
  }
  for (int i = 0; i < c.nanchors; ++i) free(c.anchors[i].name);
  free(c.anchors);
  return rc < 0 ? -1 : 0;
}

int fmbp_open(fmbParser* p, const char* path, const char* const* overrides, int noverrides, fmbDiag* diag) {
  memset(&p->doc, 0, sizeof p->doc);
  p->path = path;
  p->diag = diag;
  p->overrides = overrides;
  p->have_doc = 0;
  p->known = NULL;
  p->override_of = NULL;
  p->nnodes_cap = 0;
  p->nlooked = 0;
  p->item = p->inherited[0] = p->inherited[1] = -1;
  /* opened without blocking (a FIFO would wait for a writer) and checked on the open file: only
     a regular file of bounded size is read (a FIFO, /dev/zero or a directory never ends) */
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  struct stat st;
  if (fd < 0 || fstat(fd, &st) != 0) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "cannot open scene file: %s", strerror(errno));
    if (fd >= 0) close(fd);
    return -1;
  }
  const char* refuse = S_ISDIR(st.st_mode) ? "is a directory, expected a YAML scene file"
                       : !S_ISREG(st.st_mode)
                           ? "is not a regular file (a device, FIFO or socket), expected a YAML scene file"
                           : NULL;
  if (refuse) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "%s", refuse);
    close(fd);
    return -1;
  }
  if (st.st_size > FMB_SCENE_BYTES_MAX) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "the scene file is too large: %lld bytes, at most %d accepted",
                 (long long)st.st_size, FMB_SCENE_BYTES_MAX);
    close(fd);
    return -1;
  }
  FILE* f = fdopen(fd, "rb");
  if (!f) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 0, 0, "cannot open scene file: %s", strerror(errno));
    close(fd);
    return -1;
  }
  yaml_parser_t parser;
  yaml_parser_initialize(&parser);
  yaml_parser_set_input_file(&parser, f);
  const int rc = compose(p, &parser, f);
  yaml_parser_delete(&parser);
  fclose(f);
  if (rc) return -1;

  /* the top-level keys as the loader reads them (engine/scene.c): the first two are required */
  char top[400] = "";
  for (size_t i = 0, used = 0; fmb_scene_keys[i] && used + 40 < sizeof top; ++i)
    used += (size_t)snprintf(top + used, sizeof top - used, "%s%s",
                             i == 0   ? ""
                             : i == 2 ? " (and optionally "
                                      : ", ",
                             fmb_scene_keys[i]);
  if (!yaml_document_get_root_node(&p->doc)) {
    fmb_diag_set(diag, FMB_EXIT_BAD_INPUT, path, 1, 1, "the scene file is empty: expected a mapping with keys %s)",
                 top);
    return -1;
  }
  if (!fmbp_is_map(p, fmbp_root(p)))
    return fmb_parse_error(p, fmbp_root(p), "expected a mapping with keys %s) at the top, found %s", top,
                           node_kind(fmbp_node(p, fmbp_root(p))));
  grow_override_marks(p);
  if (check_duplicates(p)) return -1;
  for (int i = 0; i < noverrides; ++i)
    if (apply_override(p, i)) return -1;
  if (check_duplicates(p)) return -1;
  grow_override_marks(p);
  p->known = calloc((size_t)p->nnodes_cap + 1, 1);
  return p->known ? 0 : -1;
}

void fmbp_close(fmbParser* p) {
  if (p->have_doc) yaml_document_delete(&p->doc);
  free(p->known);
  free(p->override_of);
  p->known = NULL;
  p->override_of = NULL;
  p->have_doc = 0;
}
