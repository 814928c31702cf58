/**
 * @file fesd.h
 * @brief libfesd umbrella header: FESD (Finite Elements with Switch Detection)
 *        integrator for piecewise-smooth (Filippov) ODEs, its semismooth Newton
 *        solver, Runge-Kutta tableaus and direct optimal control (fesd_ocp.h).
 */
#ifndef FESD_H
#define FESD_H
#include "fesd_status.h"
#include "fesd_rk.h"
#include "fesd_ncp.h"
#include "fesd_integrator.h"
#include "fesd_ocp.h"
#endif
