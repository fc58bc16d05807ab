#ifndef FLEXMBD_BUILTIN_H
#define FLEXMBD_BUILTIN_H
#include "flexmbd_plugin.h"
/* a registry holding the types shipped with flexmbd (fmb_builtin_plugin), made on first use */
FMB_API const fmbRegistry* fmb_builtin_registry(void);
#endif
