#ifndef FLEXMBD_BUILTIN_H
#define FLEXMBD_BUILTIN_H
#include "flexmbd.h"
/* the registry of every type shipped with flexmbd */
const fmbRegistry* fmb_builtin_registry(void);
#endif
