/* serve_protocol.h — what `flexmbd sweep --runner serve` (sweep_serve.c) and its runners
 * (`flexmbd run SCENE --serve`, run_serve.c) say to each other.
 *
 * Code from data cannot get in, and nothing a run prints can be taken for an answer:
 *  - the channel is two pipes of their own, the runner's fd 3 (requests) and fd 4 (answers); its
 *    stdin is /dev/null and its stdout is not read, so a plugin that prints does not shift rows;
 *  - every field is sent with its length (no separator a value could hold: a tab or a line break
 *    inside a value, or inside the output folder's name, stays inside that one field);
 *  - every request carries a number the answer repeats: an answer for another request (a
 *    runner out of step for whatever reason) is refused, the runner killed, the run `crashed`.
 * Request: "Q SEQ NFIELDS\n" then NFIELDS times "LEN:" LEN bytes "\n"; field 0 is the run's CSV,
 * the others its overrides PATH=VALUE. Answer: "A SEQ EXIT NSTATS NMSG\n" then the stats line
 * (NSTATS bytes) and the message (NMSG bytes). */
#ifndef FLEXMBD_SERVE_PROTOCOL_H
#define FLEXMBD_SERVE_PROTOCOL_H
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#define FMB_SERVE_REQUEST_FD 3
#define FMB_SERVE_ANSWER_FD 4
#define FMB_SERVE_MAX_FIELDS 1024
#define FMB_SERVE_MAX_FIELD 65536
#define FMB_SERVE_MAX_ANSWER 16384 /* header, stats and message together */

/* the request bytes (malloc'd, *len of them), or NULL when out of memory */
char* fmb_serve_request(uint64_t seq, const char* const* fields, int n, size_t* len);
/* one request from `in`: 1 with *seq and n fields (malloc'd array of malloc'd strings; free with
   fmb_serve_free_fields), 0 at the end of input, -1 when malformed */
int fmb_serve_read_request(FILE* in, uint64_t* seq, char*** fields, int* n);
void fmb_serve_free_fields(char** fields, int n);
/* the answer bytes into buf (at most FMB_SERVE_MAX_ANSWER; stats and msg cut to fit); the length */
size_t fmb_serve_answer(char* buf, uint64_t seq, int exit_code, const char* stats, const char* msg);
/* an answer at the start of buf[0..n): the bytes it takes (> 0) with its parts (stats and msg
   copied, NUL-terminated, cut to their buffers), 0 when incomplete, -1 when malformed */
long fmb_serve_parse_answer(const char* buf, size_t n, uint64_t* seq, int* exit_code, char* stats, size_t nstats,
                            char* msg, size_t nmsg);
#endif
