/* fesd_tableau_get dispatch, the explicit tableaus and family names. */
#include <string.h>

#include "rk_internal.h"

static const char *const family_names[FESD_RK_NUM_FAMILIES] = {
    [FESD_RK_RADAU_IIA] = "radau",
    [FESD_RK_GAUSS_LEGENDRE] = "gauss",
    [FESD_RK_LOBATTO_IIIA] = "lobatto3a",
    [FESD_RK_LOBATTO_IIIC] = "lobatto3c",
    [FESD_RK_EXPLICIT] = "erk",
};

const char *fesd_rk_family_name(fesd_rk_family family) {
  if ((int)family < 0 || (int)family >= FESD_RK_NUM_FAMILIES) return NULL;
  return family_names[family];
}

int fesd_rk_family_parse(const char *name, fesd_rk_family *out) {
  if (!name || !out) return FESD_ERR_NULL;
  if (strcmp(name, "explicit") == 0) { /* an alias of "erk" */
    *out = FESD_RK_EXPLICIT;
    return FESD_OK;
  }
  for (int f = 0; f < FESD_RK_NUM_FAMILIES; ++f) {
    if (strcmp(name, family_names[f]) == 0) {
      *out = (fesd_rk_family)f;
      return FESD_OK;
    }
  }
  return FESD_ERR_INVALID_ARG;
}

int fesd_rk_order(fesd_rk_family family, int s) {
  switch (family) {
  case FESD_RK_RADAU_IIA:
    return (s >= 1 && s <= FESD_RK_MAX_STAGES) ? 2 * s - 1 : -1;
  case FESD_RK_GAUSS_LEGENDRE:
    return (s >= 1 && s <= FESD_RK_MAX_STAGES) ? 2 * s : -1;
  case FESD_RK_LOBATTO_IIIA:
  case FESD_RK_LOBATTO_IIIC:
    return (s >= 2 && s <= FESD_RK_MAX_STAGES) ? 2 * s - 2 : -1;
  case FESD_RK_EXPLICIT:
    return (s >= 1 && s <= 4) ? s : -1;
  default:
    return -1;
  }
}

/* s=1 explicit Euler, s=2 Heun, s=3 Kutta's third-order method, s=4 classic RK4. */
static void explicit_tableau(int s, fesd_tableau *t) {
  switch (s) {
  case 1:
    t->b[0] = 1.0;
    break;
  case 2:
    t->c[1] = 1.0;
    t->A[1][0] = 1.0;
    t->b[0] = t->b[1] = 0.5;
    break;
  case 3:
    t->c[1] = 0.5;
    t->c[2] = 1.0;
    t->A[1][0] = 0.5;
    t->A[2][0] = -1.0;
    t->A[2][1] = 2.0;
    t->b[0] = t->b[2] = 1.0 / 6.0;
    t->b[1] = 2.0 / 3.0;
    break;
  default: /* 4 */
    t->c[1] = t->c[2] = 0.5;
    t->c[3] = 1.0;
    t->A[1][0] = 0.5;
    t->A[2][1] = 0.5;
    t->A[3][2] = 1.0;
    t->b[0] = t->b[3] = 1.0 / 6.0;
    t->b[1] = t->b[2] = 1.0 / 3.0;
    break;
  }
}

int fesd_tableau_get(fesd_rk_family family, int s, fesd_tableau *out) {
  if (!out) return FESD_ERR_NULL;
  int order = fesd_rk_order(family, s);
  if (order < 0) return FESD_ERR_UNSUPPORTED_TABLEAU;

  fesd_tableau t; /* built here; *out is only written on success */
  memset(&t, 0, sizeof t);
  t.family = family;
  t.s = s;
  t.order = order;

  int rc = FESD_OK;
  switch (family) {
  case FESD_RK_EXPLICIT:
    explicit_tableau(s, &t);
    t.is_explicit = 1;
    break;
  case FESD_RK_LOBATTO_IIIC:
    rc = fesd__collocation_nodes(family, s, t.c);
    if (rc == FESD_OK) rc = fesd__lobatto3c_ab(s, t.c, t.A, t.b);
    t.stiffly_accurate = 1;
    break;
  default: /* Radau IIA, Gauss-Legendre, Lobatto IIIA: collocation */
    rc = fesd__collocation_nodes(family, s, t.c);
    if (rc == FESD_OK) rc = fesd__collocation_ab(s, t.c, t.A, t.b);
    t.stiffly_accurate = (family != FESD_RK_GAUSS_LEGENDRE);
    break;
  }
  if (rc != FESD_OK) return rc;
  if (t.stiffly_accurate) memcpy(t.A[s - 1], t.b, (size_t)s * sizeof(double));
  t.c_end_is_one = (t.c[s - 1] == 1.0);
  *out = t;
  return FESD_OK;
}
