/* version.c — what a program asks the library it runs with at run time: its release (against the
 * header it was compiled with, or what `flexmbd --version` printed) and its plugin ABI. */
#include "flexmbd_plugin.h"

#ifndef FLEXMBD_VERSION
#define FLEXMBD_VERSION "unknown"
#endif

const char* fmb_version(void) { return FLEXMBD_VERSION; }

int fmb_plugin_abi(void) { return FMB_PLUGIN_ABI; }
