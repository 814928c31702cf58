/* Internal (not installed) hooks of the integrator. A workspace whose fesd_ncp_set_rows only
 * orders the rows; the pattern of a selection is built and analysed at its first Jacobian (a
 * solve or sensitivity that needs one), so a selection whose solves start converged never pays
 * for the analysis (the integrator's ordinary steps). A failure of that analysis
 * (FESD_ERR_NOMEM, FESD_ERR_LINSOLVE) is returned by the solve that needed it and tried again
 * at the next. */
#ifndef FESD_NCP_DEFER_H
#define FESD_NCP_DEFER_H

#include "fesd_ncp.h"

/* Defer the analysis of the selections set from now on. */
void fesd__ncp_defer_analysis(fesd_ncp *ws);

/* Bounds lo <= z_i <= hi of one unknown (the others keep theirs): the integrator moves only
 * the element lengths, fesd_ncp_set_bounds would check and copy all n every step. */
int fesd__ncp_set_bound(fesd_ncp *ws, int i, double lo, double hi);

#endif
