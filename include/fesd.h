/**
 * @file fesd.h
 * @brief libfesd umbrella header: FESD (Finite Elements with Switch Detection)
 *        integrator for piecewise-smooth (Filippov) ODEs, its semismooth Newton
 *        solver and Runge-Kutta tableaus.
 */
#ifndef FESD_H
#define FESD_H
#include "fesd_status.h"
#include "fesd_rk.h"
#include "fesd_ncp.h"
#include "fesd_integrator.h"
#endif
