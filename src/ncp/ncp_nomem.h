/* Internal (not installed): allocation failures met by a solver workspace. A caller that
 * tries several solves and may recover from a failed one by another path (the integrator's
 * step) compares this count before and after, so that a result reached after a failed
 * allocation is reported as FESD_ERR_NOMEM and not as a different, silent FESD_OK. */
#ifndef FESD_NCP_NOMEM_H
#define FESD_NCP_NOMEM_H

#include "fesd_ncp.h"

/* FESD_ERR_NOMEM results of the analyses, factorizations and solves of ws since setup. */
int fesd__ncp_nomem_count(const fesd_ncp *ws);

#endif
