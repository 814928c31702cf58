/* Independent reference for random piecewise-affine Filippov systems (tests/prop, tests/fuzz).
 *
 * System: K independent subsystems, each with one affine switching function
 * c_k(x) = a_k'x + b_k and two modes f_{k,i}(x,u) = A_{k,i} x + d_{k,i} + B_{k,i} u
 * (mode 0 where c_k > 0, mode 1 where c_k < 0); x' = sum_k f_{k,mode_k}. On sliding surfaces
 * the Filippov field is sum_k (theta_k f_{k,0} + (1 - theta_k) f_{k,1}) with theta_k in (0,1)
 * for the sliding subsystems, fixed by tangency to every sliding surface.
 *
 * Reference (pwa_reference): event-driven. Without sliding the motion is affine and is
 * evaluated exactly with the matrix exponential of the augmented matrix [[A, d, B]; 0] (pwa_expm:
 * scaling and squaring + Taylor); switching functions are sampled on a grid (sample_dt),
 * crossings bracketed and located by Brent's method to ~1e-15 in t, extrema between samples
 * located the same way (grazing). While some subsystem slides, classical RK4 with step rk_h and
 * compensated summation integrates the sliding field (piecewise-constant fields: the sliding
 * field is constant and RK4 exact, steps of sample_dt; otherwise error ~ rk_h^4: rk_h and
 * rk_h / 2 agree to 1e-15 on these systems, tests/prop/test_pwa_ref.c),
 * events (surfaces reached, theta_k reaching 0 or 1) located by Brent's method on the
 * one-step RK4 map. Sensitivities dx/dx0, dx/du: exact variational flow (expm) in regions, RK4
 * on the variational equation of the sliding field, saltation matrices at crossings and
 * entries (the field is continuous at sliding exits: no jump).
 *
 * Anything that would make the reference (or the comparison) ill-conditioned is refused with
 * a nonzero status: events closer than dt_min to each other or to 0 and T, arrivals or departures
 * nearly tangent to a surface, grazing, theta within theta_margin of 0 or 1 at an entry or
 * crossing, nearly singular sliding systems, slow exits, too many events, blow-up, and surfaces
 * reached where the continuation is not unique: every configuration (mode 0, mode 1, sliding)
 * of the subsystems then on their surfaces is tried, and exactly one must be consistent (thetas
 * in (0, 1), the others' fields leaving into their sides), every other clearly inconsistent.
 * Does not use libfesd. */
#ifndef PWA_REF_H
#define PWA_REF_H
#include <stdint.h>

#define PWA_MAX_NX 4
#define PWA_MAX_K 4
#define PWA_MAX_NU 2
#define PWA_MAX_EV 512
#define PWA_MAX_OUT 64
#define PWA_MAX_AUG (PWA_MAX_NX + 1 + PWA_MAX_NU)

typedef struct {
  int nx, K, nu;
  double a[PWA_MAX_K][PWA_MAX_NX], b[PWA_MAX_K];
  double A[PWA_MAX_K][2][PWA_MAX_NX][PWA_MAX_NX]; /* row-major */
  double d[PWA_MAX_K][2][PWA_MAX_NX];
  double B[PWA_MAX_K][2][PWA_MAX_NX][PWA_MAX_NU];
  int affine; /* 0: every A is zero (piecewise-constant fields) */
} pwa_sys;

/* configuration of a subsystem; event kinds numbered as fesd_event_kind */
enum { PWA_MODE0 = 0, PWA_MODE1 = 1, PWA_SLIDE = 2 };
enum { PWA_CROSSING = 0, PWA_ENTRY = 1, PWA_EXIT = 2 };

typedef struct {
  double t;
  int sys, kind;
  int before, after; /* PWA_MODE0 / PWA_MODE1 / PWA_SLIDE */
} pwa_event;

typedef struct {
  double T;
  int n_out;           /* states wanted at t_out[0..n_out-1], ascending in (0, T] */
  const double *t_out;
  int sens;            /* 1: sensitivities */
  double dt_min;       /* smallest accepted distance between events, and to 0 and T */
  double trans_min;    /* smallest |a'f| / (|a| max(1, |f|)) at a surface (both sides) */
  double theta_margin; /* sliding theta in [margin, 1 - margin] at entries and crossings */
  double graze_margin; /* smallest |c|/|a| (or theta distance) at an extremum between samples */
  double exit_rate_min;/* smallest |d theta/dt| at a sliding exit */
  double start_margin; /* smallest |c_k(x0)|/|a_k| */
  double sample_dt;    /* sampling grid without sliding */
  double rk_h;         /* RK4 step while sliding (affine fields) */
  double x_max;        /* blow-up bound on |x|_inf */
  int max_events;
} pwa_opts;

/* reasons for refusing a trajectory */
enum {
  PWA_OK = 0,
  PWA_DEGEN_START,       /* x0 too close to a surface */
  PWA_DEGEN_CLOSE,       /* events closer than dt_min (or to 0, T) */
  PWA_DEGEN_TANGENT,     /* arrival or departure nearly tangent to a surface */
  PWA_DEGEN_GRAZING,     /* a switching function (or theta) nearly touches its bound */
  PWA_DEGEN_THETA,       /* theta of a sliding subsystem near 0 or 1 at an event */
  PWA_DEGEN_SINGULAR,    /* sliding system nearly singular */
  PWA_DEGEN_SLOW_EXIT,   /* theta reaches its bound with small rate */
  PWA_DEGEN_MANY,        /* more than max_events events */
  PWA_DEGEN_BLOWUP,      /* |x| > x_max */
  PWA_DEGEN_NONUNIQUE,   /* at a surface: not exactly one Filippov continuation, with margins */
  PWA_DEGEN_ARG          /* bad arguments */
};

typedef struct {
  int status;      /* PWA_OK or PWA_DEGEN_* */
  double t_fail;   /* time of the refusal */
  int n_ev;
  pwa_event ev[PWA_MAX_EV];
  int n_cross, n_entry, n_exit;
  int n_entry_multi, n_cross_multi;     /* entries / crossings while another subsystem slides */
  double x[PWA_MAX_NX];                 /* x(T) */
  double x_out[PWA_MAX_OUT][PWA_MAX_NX];
  double Sx[PWA_MAX_NX][PWA_MAX_NX];    /* dx(T)/dx0, row-major [state][x0 component] */
  double Su[PWA_MAX_NX][PWA_MAX_NU];    /* dx(T)/du */
  int cfg_end[PWA_MAX_K];
  double t_slide;                       /* time spent with some subsystem sliding */
  int max_sliding;                      /* most subsystems sliding at once */
} pwa_result;

void pwa_opts_default(pwa_opts *o, double T);
const char *pwa_status_name(int status);

/* E = expm(M), n x n row-major (n <= PWA_MAX_AUG). */
void pwa_expm(int n, const double *M, double *E);

/* The reference from (0, x0) with constant u (NULL when nu == 0). Returns r->status. */
int pwa_reference(const pwa_sys *S, const double *x0, const double *u, const pwa_opts *o, pwa_result *r);

/* Field of subsystem k in mode i (f, nx values) and its switching function. */
void pwa_mode_field(const pwa_sys *S, int k, int i, const double *x, const double *u, double *f);
double pwa_c(const pwa_sys *S, int k, const double *x);

/* libfesd callbacks (user = const pwa_sys *); the signatures match fesd_field_fn etc. */
int pwa_cb_field(int sys, int mode, double t, const double *x, const double *u, double *f, void *user);
int pwa_cb_switch(int sys, double t, const double *x, const double *u, double *c, void *user);
int pwa_cb_field_jac(int sys, int mode, double t, const double *x, const double *u, double *dfdx,
                     double *dfdu, void *user);
int pwa_cb_switch_jac(int sys, double t, const double *x, const double *u, double *dcdx, double *dcdu,
                      void *user);

/* seeded generator (splitmix64) */
typedef struct {
  uint64_t s;
} pwa_rng;
uint64_t pwa_rng_next(pwa_rng *r);
double pwa_uniform(pwa_rng *r, double lo, double hi);
int pwa_int(pwa_rng *r, int lo, int hi); /* in [lo, hi] */

/* Random system: the tangential pushes beta_k R a_k (R: rotation by 90 degrees in the
 * (x0, x1) plane) make x' the Hamiltonian flow of V = sum_k beta_k |c_k| (trajectories circle
 * the intersection of the surfaces, crossing each several times per unit time); normal pushes
 * gamma_k a_k toward the surface (probability slide_prob) make surfaces attractive (sliding);
 * a random drift and, when affine, random A (entries up to a_scale, plus a rotation up to rot
 * in the (x0, x1) plane) move trajectories in and out of sliding. */
typedef struct {
  int nx, K, nu;
  int affine;
  double a_scale, rot, slide_prob, drift;
  double beta_lo, beta_hi;
} pwa_gen;
void pwa_random_system(pwa_sys *S, pwa_rng *rng, const pwa_gen *g);
void pwa_random_x0(const pwa_sys *S, pwa_rng *rng, double *x0);

#endif
