/*
 * flexmbd_cli.h — what the library shares with the flexmbd program and nothing else: the safe
 * file writer with its input-file guard, the "did you mean" rule and the XML escaper. Not
 * installed and not part of the public API (flexmbd.h, flexmbd_plugin.h): these serve the
 * program's policy (which files a command may replace, how a typo is answered), may change with
 * it, and are exported from the shared library only because the program links that library.
 */
#ifndef FLEXMBD_CLI_SUPPORT_H
#define FLEXMBD_CLI_SUPPORT_H

#include "flexmbd.h"

#ifdef __cplusplus
extern "C" {
#endif

/* s as XML text or attribute value (& < > " ' escaped, control characters other than \n \t
   dropped): the VTK collection, JUnit reports */
FMB_API void fmb_write_xml_text(FILE* f, const char* s);

/* ---------------------------------------------------------------------------------------------
 * Writing a file without losing one (engine/safe_file.c): the content goes to a temporary file
 * beside `path` that replaces it only on fmb_safe_close(f, 1); fmb_safe_close(f, 0) removes the
 * temporary file and leaves `path` as it was. "-" and non-regular paths (a FIFO, /dev/null) are
 * written straight through and never removed. The caller owns the handle until fmb_safe_close.
 * ------------------------------------------------------------------------------------------- */
typedef struct fmbSafeFile fmbSafeFile;
/* A set of input files that a writer must not replace (fmbInputs): whatever name or link leads to
   one (same device and inode), until the noted name no longer leads to that file (deleted or
   replaced since: its inode may be reused). There is no process-wide list: each model keeps the
   set of the files fmb_load read for it (the scene, its table files, the scene's plugins;
   fmb_model_inputs) and the writers of its runs check against it; a program that reads more
   (samples, references, plugins it loads itself) keeps a set of its own and opens its files with
   fmb_safe_open_guarded. A set has its own lock: it may be shared by threads.
   note: 0, or -1 (not a regular file, or out of memory); notes are counted, each undone by one
   forget. add: every file of `from` noted in `to` (0, or -1). at: 1 when `path` is one of the set's
   files, with the name it was noted under in name[namelen] (may be NULL), else 0. */
typedef struct fmbInputs fmbInputs;
FMB_API fmbInputs* fmb_inputs_new(void); /* NULL when out of memory */
FMB_API void fmb_inputs_free(fmbInputs* in);
FMB_API int fmb_inputs_note(fmbInputs* in, const char* path);
FMB_API void fmb_inputs_forget(fmbInputs* in, const char* path);
FMB_API int fmb_inputs_add(fmbInputs* to, const fmbInputs* from);
FMB_API int fmb_inputs_at(const fmbInputs* in, const char* path, char* name, size_t namelen);
FMB_API int fmb_inputs_count(const fmbInputs* in);
/* the files fmb_load read for m (valid while m is); NULL for a NULL model */
FMB_API const fmbInputs* fmb_model_inputs(const fmbModel* m);
/* NULL with the reason in err on failure, among them a target that is one of `inputs` (may be NULL:
   nothing refused on that ground; fmb_safe_open is fmb_safe_open_guarded with NULL) */
FMB_API fmbSafeFile* fmb_safe_open_guarded(const char* path, const fmbInputs* inputs, char* err, size_t errlen);
FMB_API fmbSafeFile* fmb_safe_open(const char* path, char* err, size_t errlen);
FMB_API FILE* fmb_safe_stream(fmbSafeFile* f); /* a stdio stream over it (closed by fmb_safe_close) */
FMB_API int fmb_safe_fd(const fmbSafeFile* f);
FMB_API int fmb_safe_is_temporary(const fmbSafeFile* f);
/* the file to write when another program writes it (gnuplot): the temporary file, or the target
   written through; NULL for stdout */
FMB_API const char* fmb_safe_write_path(const fmbSafeFile* f);
/* keep != 0: put the content in place (rename); 0: discard it. 0, or -1 with errno on failure */
FMB_API int fmb_safe_close(fmbSafeFile* f, int keep);

/* "did you mean": of words[0..n) (NULL entries skipped), the nearest to `typed` when `typed` is
   a typo of it (an edit distance, with adjacent transpositions, of 1 in a word of up to 4
   letters, 2 from 5 on), else NULL. The scene loader's unknown keys and the program's unknown
   commands are matched by this one rule. */
FMB_API const char* fmb_nearest_word(const char* typed, const char* const* words, int n);

#ifdef __cplusplus
}
#endif
#endif
