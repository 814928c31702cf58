/* Reference runs of the C API for the Python tests (python/tests/test_against_c.py): the same
 * problems (src/problems) integrated by libfesd directly, printed with 17 digits.
 *
 *   fesd_py_reference layout
 *   fesd_py_reference fixed PROBLEM METHOD FAMILY STAGES N_FE NSIM T [u...]   (fesd_step, sensitivities)
 *   fesd_py_reference integrate PROBLEM FAMILY STAGES RTOL ATOL T [u...]     (fesd_integrate)
 *   fesd_py_reference grid PROBLEM FAMILY STAGES RTOL ATOL N t_1..t_N [u...] (fesd_integrate_grid)
 *   fesd_py_reference time PROBLEM FAMILY STAGES NSIM T REPS                 (CPU us per fesd_step)
 *   fesd_py_reference ocp_step_eq METHOD FAMILY STAGES N_FE N_CTRL [HESSIAN] (fesd_ocp_solve of the
 *                     paper's ocp_step_eq from its control guess; HESSIAN 0..3 as fesd_ocp_hessian)
 *   fesd_py_reference ocp_layout                                             (every field of the OCP structs)
 *
 * Output: one record per line, "name v1 v2 ...". */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fesd.h"
#include "problems/problems.h"

#define OFF(T, f) printf("offset %s.%s %zu\n", #T, #f, offsetof(T, f))

static int layout(void) {
  printf("size fesd_ncp_settings %zu\n", sizeof(fesd_ncp_settings));
  OFF(fesd_ncp_settings, max_iter); OFF(fesd_ncp_settings, armijo); OFF(fesd_ncp_settings, max_backtracks);
  OFF(fesd_ncp_settings, sigma0); OFF(fesd_ncp_settings, lm_mu0); OFF(fesd_ncp_settings, slow_ratio); OFF(fesd_ncp_settings, log_user);
  printf("size fesd_settings %zu\n", sizeof(fesd_settings));
  OFF(fesd_settings, n_fe); OFF(fesd_settings, newton_tol); OFF(fesd_settings, cc_tol); OFF(fesd_settings, exit_rows);
  OFF(fesd_settings, coarse_tol); OFF(fesd_settings, max_elements); OFF(fesd_settings, ncp);
  printf("size fesd_model %zu\n", sizeof(fesd_model));
  OFF(fesd_model, n_modes); OFF(fesd_model, sign); OFF(fesd_model, field); OFF(fesd_model, sw_jac);
  OFF(fesd_model, sparsity); OFF(fesd_model, time_dependent); OFF(fesd_model, drift); OFF(fesd_model, drift_sparsity);
  OFF(fesd_model, n_roots); OFF(fesd_model, roots); OFF(fesd_model, root_dir);
  printf("size fesd_step_info %zu\n", sizeof(fesd_step_info));
  OFF(fesd_step_info, fallback); OFF(fesd_step_info, residual); OFF(fesd_step_info, failed_callback);
  OFF(fesd_step_info, failed_time); OFF(fesd_step_info, failed_path); OFF(fesd_step_info, last_time);
  printf("size fesd_event %zu\n", sizeof(fesd_event));
  OFF(fesd_event, sys); OFF(fesd_event, n_after); OFF(fesd_event, before); OFF(fesd_event, after);
  printf("size fesd_step_data %zu\n", sizeof(fesd_step_data));
  OFF(fesd_step_data, h); OFF(fesd_step_data, mu); OFF(fesd_step_data, n_theta); OFF(fesd_step_data, nx);
  printf("size fesd_tolerances %zu\n", sizeof(fesd_tolerances));
  OFF(fesd_tolerances, atol_v); OFF(fesd_tolerances, h_min); OFF(fesd_tolerances, max_steps);
  printf("size fesd_integrate_info %zu\n", sizeof(fesd_integrate_info));
  OFF(fesd_integrate_info, t); OFF(fesd_integrate_info, n_done); OFF(fesd_integrate_info, h_next);
  printf("size fesd_stats %zu\n", sizeof(fesd_stats));
  OFF(fesd_stats, events); OFF(fesd_stats, time); OFF(fesd_stats, mean_iter_switch_step);
  return 0;
}

/* every field of the OCP structs (python/tests/test_ocp.py checks all of them) */
static int ocp_layout(void) {
  printf("size fesd_ocp_problem %zu\n", sizeof(fesd_ocp_problem));
  OFF(fesd_ocp_problem, model); OFF(fesd_ocp_problem, n_ctrl); OFF(fesd_ocp_problem, t0); OFF(fesd_ocp_problem, tf);
  OFF(fesd_ocp_problem, x0); OFF(fesd_ocp_problem, x0_lb); OFF(fesd_ocp_problem, x0_ub); OFF(fesd_ocp_problem, x_lb);
  OFF(fesd_ocp_problem, x_ub); OFF(fesd_ocp_problem, u_lb); OFF(fesd_ocp_problem, u_ub);
  OFF(fesd_ocp_problem, lagrange); OFF(fesd_ocp_problem, n_lagrange_lsq); OFF(fesd_ocp_problem, lagrange_lsq);
  OFF(fesd_ocp_problem, mayer); OFF(fesd_ocp_problem, n_mayer_lsq); OFF(fesd_ocp_problem, mayer_lsq);
  OFF(fesd_ocp_problem, n_l1); OFF(fesd_ocp_problem, l1); OFF(fesd_ocp_problem, l1_weight);
  OFF(fesd_ocp_problem, n_path); OFF(fesd_ocp_problem, path); OFF(fesd_ocp_problem, path_lb);
  OFF(fesd_ocp_problem, path_ub); OFF(fesd_ocp_problem, n_term); OFF(fesd_ocp_problem, terminal);
  OFF(fesd_ocp_problem, term_lb); OFF(fesd_ocp_problem, term_ub); OFF(fesd_ocp_problem, user);
  printf("size fesd_ocp_settings %zu\n", sizeof(fesd_ocp_settings));
  OFF(fesd_ocp_settings, integrator); OFF(fesd_ocp_settings, hessian); OFF(fesd_ocp_settings, max_iter);
  OFF(fesd_ocp_settings, tol_stat); OFF(fesd_ocp_settings, tol_feas); OFF(fesd_ocp_settings, tol_comp);
  OFF(fesd_ocp_settings, penalty0); OFF(fesd_ocp_settings, penalty_max); OFF(fesd_ocp_settings, armijo);
  OFF(fesd_ocp_settings, backtrack); OFF(fesd_ocp_settings, max_backtracks); OFF(fesd_ocp_settings, soc);
  OFF(fesd_ocp_settings, nonmonotone); OFF(fesd_ocp_settings, reg_primal); OFF(fesd_ocp_settings, reg_dual);
  OFF(fesd_ocp_settings, qp_tol); OFF(fesd_ocp_settings, qp_max_iter); OFF(fesd_ocp_settings, stall_window);
  OFF(fesd_ocp_settings, qp_backend); OFF(fesd_ocp_settings, init); OFF(fesd_ocp_settings, presolve);
  OFF(fesd_ocp_settings, presolve_n_fe); OFF(fesd_ocp_settings, verbose); OFF(fesd_ocp_settings, log);
  OFF(fesd_ocp_settings, log_user);
  printf("size fesd_ocp_info %zu\n", sizeof(fesd_ocp_info));
  OFF(fesd_ocp_info, status); OFF(fesd_ocp_info, iterations); OFF(fesd_ocp_info, qp_iterations);
  OFF(fesd_ocp_info, qp_elastic); OFF(fesd_ocp_info, qp_failures); OFF(fesd_ocp_info, line_search_trials);
  OFF(fesd_ocp_info, soc_steps); OFF(fesd_ocp_info, hessian_updates); OFF(fesd_ocp_info, hessian_skipped);
  OFF(fesd_ocp_info, hessian_resets); OFF(fesd_ocp_info, integrations); OFF(fesd_ocp_info, integrator_failures);
  OFF(fesd_ocp_info, integrator_flags); OFF(fesd_ocp_info, objective); OFF(fesd_ocp_info, stationarity);
  OFF(fesd_ocp_info, stationarity_rel); OFF(fesd_ocp_info, feasibility); OFF(fesd_ocp_info, complementarity);
  OFF(fesd_ocp_info, min_multiplier); OFF(fesd_ocp_info, penalty); OFF(fesd_ocp_info, max_step);
  OFF(fesd_ocp_info, time_total); OFF(fesd_ocp_info, time_integration); OFF(fesd_ocp_info, time_qp);
  OFF(fesd_ocp_info, time_other); OFF(fesd_ocp_info, hessian_fallback); OFF(fesd_ocp_info, stalled);
  OFF(fesd_ocp_info, stall_interval); OFF(fesd_ocp_info, presolve_run); OFF(fesd_ocp_info, presolve_status);
  OFF(fesd_ocp_info, presolve_iterations); OFF(fesd_ocp_info, presolve_used);
  printf("size fesd_ocp_multipliers %zu\n", sizeof(fesd_ocp_multipliers));
  OFF(fesd_ocp_multipliers, dynamics); OFF(fesd_ocp_multipliers, x0); OFF(fesd_ocp_multipliers, x_bound);
  OFF(fesd_ocp_multipliers, u_bound); OFF(fesd_ocp_multipliers, path); OFF(fesd_ocp_multipliers, terminal);
  OFF(fesd_ocp_multipliers, l1);
  return 0;
}

static void vec(const char *name, const double *v, int n) {
  printf("%s", name);
  for (int i = 0; i < n; i++) printf(" %.17g", v[i]);
  printf("\n");
}

static void events(const fesd_event *ev, int n) {
  for (int e = 0; e < n; e++) {
    printf("event %.17g %d %d %d", ev[e].t, ev[e].sys, (int)ev[e].kind, ev[e].n_before);
    for (int i = 0; i < ev[e].n_before; i++) printf(" %d", ev[e].before[i]);
    printf(" %d", ev[e].n_after);
    for (int i = 0; i < ev[e].n_after; i++) printf(" %d", ev[e].after[i]);
    printf("\n");
  }
}

static int parse_family(const char *s, fesd_rk_family *f) {
  if (!strcmp(s, "explicit")) return *f = FESD_RK_EXPLICIT, 0;
  return fesd_rk_family_parse(s, f);
}

static fesd_integrator *make(fesd_problem *P, const char *method, const char *family, int stages, int n_fe, int sens,
                             const char *const *uarg, int nuarg) {
  fesd_settings set;
  fesd_settings_default(&set);
  set.method = !strcmp(method, "standard") ? FESD_METHOD_STANDARD : FESD_METHOD_FESD;
  if (parse_family(family, &set.family)) return NULL;
  set.stages = stages;
  set.n_fe = n_fe;
  set.sensitivities = sens;
  for (int i = 0; i < nuarg && i < FESD_PROBLEM_MAX_NU; i++) P->u[i] = atof(uarg[i]);
  fesd_integrator *it = NULL;
  int st = fesd_create(&it, &P->model, &set);
  if (st) {
    fprintf(stderr, "create: %s\n", fesd_status_name(st));
    return NULL;
  }
  fesd_set_state(it, 0.0, P->x0, P->u);
  return it;
}

/* ocp_step_eq through the C API: status, info, solution, multipliers and events per interval */
static int ocp_step_eq(fesd_problem *P, const char *method, const char *family, int stages, int n_fe, int n_ctrl,
                       int hessian) {
  fesd_ocp_problem op;
  fesd_ocp_step_eq(&op, &P->model);
  op.n_ctrl = n_ctrl;
  fesd_ocp_settings s;
  fesd_ocp_settings_default(&s);
  s.integrator.method = !strcmp(method, "standard") ? FESD_METHOD_STANDARD : FESD_METHOD_FESD;
  if (parse_family(family, &s.integrator.family)) return 2;
  s.integrator.stages = stages;
  s.integrator.n_fe = n_fe;
  s.hessian = (fesd_ocp_hessian)hessian;
  fesd_ocp *o;
  int st = fesd_ocp_create(&o, &op, &s);
  if (st) {
    printf("status %d\n", st);
    return 0;
  }
  double *ug = malloc(sizeof(double) * 2 * (size_t)n_ctrl), *u = malloc(sizeof(double) * 2 * (size_t)n_ctrl);
  double *x = malloc(sizeof(double) * 4 * (size_t)(n_ctrl + 1));
  fesd_ocp_step_eq_guess(ug, n_ctrl);
  fesd_ocp_set_guess(o, NULL, ug);
  fesd_ocp_info info;
  st = fesd_ocp_solve(o, &info);
  fesd_ocp_get_solution(o, x, u);
  printf("objective %.17g\n", info.objective);
  printf("kkt %.17g %.17g %.17g %.17g\n", info.stationarity_rel, info.feasibility, info.complementarity,
         info.min_multiplier);
  printf("work %d %d %d %d\n", info.iterations, info.integrations, info.presolve_run, info.presolve_iterations);
  vec("u", u, 2 * n_ctrl);
  vec("xsol", x, 4 * (n_ctrl + 1));
  fesd_ocp_multipliers m;
  fesd_ocp_get_multipliers(o, &m);
  vec("m_dynamics", m.dynamics, 4 * n_ctrl);
  vec("m_u_bound", m.u_bound, 2 * n_ctrl);
  vec("m_l1", m.l1, 2);
  for (int k = 0; k < n_ctrl; k++) {
    const fesd_event *ev;
    int ne;
    fesd_step_data d;
    if (fesd_ocp_interval(o, k, &d, &ev, &ne) == FESD_OK) {
      printf("interval %d %d", k, d.n_elements);
      for (int e = 0; e < d.n_elements; e++) printf(" %.17g", d.h[e]);
      printf("\n");
      events(ev, ne);
    }
  }
  printf("status %d\n", st);
  fesd_ocp_free(&o);
  free(ug), free(u), free(x);
  return 0;
}

int main(int argc, char **argv) {
  if (argc >= 2 && !strcmp(argv[1], "layout")) return layout();
  if (argc >= 2 && !strcmp(argv[1], "ocp_layout")) return ocp_layout();
  if (argc >= 7 && !strcmp(argv[1], "ocp_step_eq")) {
    fesd_problem P;
    fesd_problem_get("ocp-dynamics", &P);
    return ocp_step_eq(&P, argv[2], argv[3], atoi(argv[4]), atoi(argv[5]), atoi(argv[6]),
                       argc >= 8 ? atoi(argv[7]) : 0);
  }
  if (argc < 3) {
    fprintf(stderr, "usage: see the top of reference.c\n");
    return 2;
  }
  fesd_problem P;
  if (fesd_problem_get(argv[2], &P)) {
    fprintf(stderr, "unknown problem %s\n", argv[2]);
    return 2;
  }
  const int nx = P.model.nx, nu = P.model.nu;
  int st;
  if (!strcmp(argv[1], "fixed") && argc >= 9) {
    const int nsim = atoi(argv[7]);
    const double T = atof(argv[8]);
    fesd_integrator *it = make(&P, argv[3], argv[4], atoi(argv[5]), atoi(argv[6]), 1, (const char *const *)argv + 9,
                               argc - 9);
    if (!it) return 1;
    double x[FESD_PROBLEM_MAX_NX], t;
    for (int k = 0; k < nsim; k++) {
      if ((st = fesd_step(it, P.u, T / nsim, NULL))) {
        printf("status %d\n", st);
        return 0;
      }
      fesd_get_state(it, &t, x);
      printf("t %.17g\n", t);
      vec("x", x, nx);
      const fesd_event *ev;
      int ne;
      fesd_last_events(it, &ev, &ne);
      events(ev, ne);
    }
    double Sx[FESD_PROBLEM_MAX_NX * FESD_PROBLEM_MAX_NX], Su[FESD_PROBLEM_MAX_NX * FESD_PROBLEM_MAX_NU];
    fesd_get_sensitivities(it, Sx, Su);
    vec("Sx", Sx, nx * nx);
    vec("Su", Su, nx * nu);
    fesd_stats S;
    fesd_get_stats(it, &S);
    printf("stats %d %d %d\n", S.steps, S.switch_steps, S.newton_iter);
    printf("status 0\n");
    fesd_free(&it);
    return 0;
  }
  if (!strcmp(argv[1], "time") && argc >= 8) { /* the Python benchmark's C baseline */
    const int nsim = atoi(argv[5]), reps = atoi(argv[7]);
    const double T = atof(argv[6]);
    fesd_integrator *it = make(&P, "fesd", argv[3], atoi(argv[4]), 2, 0, NULL, 0);
    if (!it) return 1;
    double best = 1e30;
    for (int r = 0; r < reps; r++) {
      struct timespec a, b;
      clock_gettime(CLOCK_THREAD_CPUTIME_ID, &a);
      fesd_set_state(it, 0.0, P.x0, P.u);
      for (int k = 0; k < nsim; k++)
        if ((st = fesd_step(it, P.u, T / nsim, NULL))) return 1;
      clock_gettime(CLOCK_THREAD_CPUTIME_ID, &b);
      const double us = ((double)(b.tv_sec - a.tv_sec) * 1e6 + (double)(b.tv_nsec - a.tv_nsec) * 1e-3) / nsim;
      if (us < best) best = us;
    }
    double x[FESD_PROBLEM_MAX_NX];
    fesd_get_state(it, NULL, x);
    vec("xend", x, nx);
    printf("us_per_step %.6g\n", best);
    fesd_free(&it);
    return 0;
  }
  if ((!strcmp(argv[1], "integrate") && argc >= 8) || (!strcmp(argv[1], "grid") && argc >= 8)) {
    const int grid = !strcmp(argv[1], "grid");
    const int n = grid ? atoi(argv[7]) : 1;
    if (grid && argc < 8 + n) return 2;
    double *tout = malloc((size_t)n * sizeof(double)), *xo = malloc((size_t)n * nx * sizeof(double));
    if (grid)
      for (int i = 0; i < n; i++) tout[i] = atof(argv[8 + i]);
    else
      tout[0] = atof(argv[7]);
    const int uoff = grid ? 8 + n : 8;
    fesd_integrator *it = make(&P, "fesd", argv[3], atoi(argv[4]), 2, 0, (const char *const *)argv + uoff, argc - uoff);
    if (!it) return 1;
    fesd_tolerances tol;
    fesd_tolerances_default(&tol);
    tol.rtol = atof(argv[5]);
    tol.atol = atof(argv[6]);
    fesd_set_tolerances(it, &tol);
    fesd_integrate_info info;
    st = grid ? fesd_integrate_grid(it, P.u, n, tout, xo, &info) : fesd_integrate(it, P.u, tout[0], &info);
    if (grid)
      for (int i = 0; i < info.n_done; i++) vec("x", xo + (size_t)i * nx, nx);
    double x[FESD_PROBLEM_MAX_NX], t;
    fesd_get_state(it, &t, x);
    printf("t %.17g\n", t);
    vec("xend", x, nx);
    printf("info %d %d %d\n", info.steps, info.rejected, info.newton_iter);
    const fesd_event *ev;
    int ne;
    fesd_event_log(it, &ev, &ne);
    events(ev, ne);
    printf("status %d\n", st);
    fesd_free(&it);
    free(tout);
    free(xo);
    return 0;
  }
  fprintf(stderr, "bad arguments\n");
  return 2;
}
