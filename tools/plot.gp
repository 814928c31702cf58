# Plots of the bench CSVs (tools/bench.sh): gnuplot -e "dir='bench/results'" tools/plot.gp
# writes order.png, pareto.png, sliding_exit.png, sensitivity.png, stewart_anitescu.png,
# anatomy.png, growth.png, workprec.png and ocp_pareto.png next to the CSVs. Curves are selected from the long-format CSVs by filters
# that return NaN for the other rows (each curve's rows are contiguous, so lines do not break).
if (!exists("dir")) dir = "bench/results"
set datafile separator ","
set terminal pngcairo size 1400,560 font ",10"
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set grid
cols = "#1f77b4 #d62728 #2ca02c #9467bd #ff7f0e #8c564b"
fams = "radau gauss lobatto3a lobatto3c erk"
famname = "Radau-IIA Gauss-Legendre Lobatto-IIIA Lobatto-IIIC explicit"
sel(c, v) = strcol(c) eq v
floor16(y) = y < 1e-16 ? 1e-16 : y # exact results (error 0) drawn at 1e-16

# ---- 1. integration order (paper Fig. integrator_order) ----
f = dir."/order.csv"
set output dir."/order.png"
set multiplot layout 1,2 title "Oscillator, N_{FE} = 2: error at T against the nominal step h (order.csv; slopes in order\\_slopes.csv)"
set xlabel "h = T / N_{sim}"
set ylabel "|x(T) - x^*(T)|_{/Symbol \245}"
do for [m in "fesd standard"] {
  set title (m eq "fesd" ? "FESD" : "standard time-stepping")
  if (m eq "fesd") { set key top left font ",8" maxrows 9 } else { unset key }
  plot for [a=1:5] for [s=(a==3||a==4 ? 2 : 1):4] f \
       using (sel("family", word(fams,a)) && column("s")==s && sel("method", m) ? column("h") : NaN):(floor16(column("err"))) \
       with linespoints lc rgb word(cols,a) pt s ps 0.6 title sprintf("%s s=%d", word(famname,a), s)
}
unset multiplot

# ---- 2. speed against error (Pareto) ----
f = dir."/pareto.csv"
set output dir."/pareto.png"
vars = "fesd standard fesd-exit0"
varname = "FESD standard FESD,exit\\_rows=0"
set multiplot layout 1,3 title "CPU time per integration against error, Radau IIA s = 1..5 (marker = s), N_{sim} doubling (pareto.csv)"
set xlabel "CPU time per integration [ms]"
set key
set key top right font ",9"
do for [p in "oscillator sign-c ocp-dynamics"] {
  set title (p eq "ocp-dynamics" ? "ocp-dynamics (T = 4): error of the switch times" : p eq "sign-c" ? "sign-c (T = 2.1, sliding exit): |x(T) - x^*(T)|" : "oscillator (T = {/Symbol p}/2): |x(T) - x^*(T)|")
  set ylabel (p eq "ocp-dynamics" ? "max_k |t_k - t_k^*|" : "error at T")
  plot for [v=1:3] for [s=1:5] f using (sel("problem", p) && sel("variant", word(vars,v)) && column("s")==s ? column("cpu_ms") : NaN):(floor16(column("err"))) \
         with linespoints lc rgb word(cols,v) pt s ps 0.7 notitle, \
       for [v=1:(p eq "sign-c" ? 3 : 2)] NaN with lines lc rgb word(cols,v) lw 2 title word(varname,v)
}
unset multiplot

# ---- 3. sliding exits: exit_rows = 1 vs the paper's formulation vs standard ----
f = dir."/sliding_exit.csv"
set output dir."/sliding_exit.png"
set terminal pngcairo size 1200,900 font ",10"
set key below
set multiplot layout 2,2 title "Leaving a sliding mode, Radau IIA s = 2 (circles), 3 (squares) (sliding\\_exit.csv)"
set xlabel "N_{sim}"
set format x "%g"
do for [p in "sign-c slide-exit-2d"] {
  do for [c in "err_state err_exit"] {
    set title sprintf("%s: %s", p, c eq "err_state" ? "state error at T" : "exit-time error")
    set ylabel (c eq "err_state" ? "|x(T) - x^*(T)|" : "|t_{exit} - t_{exit}^*|")
    plot for [v=1:3] for [s=2:3] f using (sel("problem", p) && sel("variant", word(vars,v)) && column("s")==s ? column("nsim") : NaN):(floor16(column(c))) \
           with linespoints lc rgb word(cols,v) pt (s==2 ? 7 : 5) ps 0.7 notitle, \
         for [v=1:3] NaN with lines lc rgb word(cols,v) lw 2 title word(varname,v)
  }
}
unset multiplot

# ---- 4. sensitivities ----
f = dir."/sensitivity.csv"
set output dir."/sensitivity.png"
set terminal pngcairo size 800,600 font ",10"
set format x "10^{%L}"
set key inside bottom right
set title "Oscillator: error of dx(T)/dx_0 (sensitivity.csv)"
set xlabel "h = T / N_{sim}"
set ylabel "max |S - X^*(T)|"
set key inside bottom right
tabs = "radau:2 radau:3 radau:4 gauss:2"
tab(i) = word(tabs, i)
meths = "fesd standard"
plot for [i=1:4] for [k=1:2] f \
     using (strcol("family").":".strcol("s") eq tab(i) && sel("method", word(meths,k)) ? column("h") : NaN):"err_sens" \
     with linespoints lc rgb word(cols,i) dt k pt (k==1 ? 7 : 4) ps 0.7 title sprintf("%s %s", word(meths,k), tab(i))

# ---- 5. Stewart-Anitescu (paper Fig. ivp_problem left) ----
f = dir."/sa_curves.csv"
set output dir."/stewart_anitescu.png"
set terminal pngcairo size 1200,500 font ",10"
unset logscale
set format x "%g"
set format y "%g"
set multiplot layout 1,2 title "Stewart-Anitescu: V(x_0) and dV/dx_0, Gauss-Legendre s = 2, N_{FE} = 25, one step (sa\\_curves.csv)"
set xlabel "x_0"
set key inside top left
set title "V(x_0)"
set ylabel "V"
plot f using "x0":"V_exact" with lines lc black lw 2 title "exact", \
     '' using "x0":"V_fesd" every 5 with points lc rgb word(cols,1) pt 7 ps 0.5 title "FESD", \
     '' using "x0":"V_std" with lines lc rgb word(cols,2) title "standard"
set title "dV/dx_0"
set ylabel "dV/dx_0"
plot f using "x0":"dV_exact" with lines lc black lw 2 title "exact", \
     '' using "x0":"dV_fesd" every 5 with points lc rgb word(cols,1) pt 7 ps 0.5 title "FESD", \
     '' using "x0":"dV_std" with lines lc rgb word(cols,2) title "standard"
unset multiplot

# ---- 6. cost anatomy ----
f = dir."/anatomy.csv"
set output dir."/anatomy.png"
set terminal pngcairo size 1900,700 font ",10"
set rmargin 10
set title "Share of the time of one integration (anatomy.csv); label: problem method s N_{sim} max\\_sweeps backend"
unset xlabel
set ylabel "share of wall time"
set yrange [0:1]
set style data histograms
set style histogram rowstacked
set style fill solid 0.8 border -1
set boxwidth 0.75
set xtics rotate by -40 font ",8"
set key outside right
unset grid
set grid ytics
lab(a) = sprintf("%s %s s%d N%d sw%d %s", strcol("problem"), strcol("method"), column("s"), column("nsim"), column("max_sweeps"), strcol("backend"))
plot f using "share_eval":xtic(lab(0)) lc rgb word(cols,1) title "residual + Jacobian", \
     '' using "share_linsolve" lc rgb word(cols,2) title "factorize + solve", \
     '' using "share_solver_other" lc rgb word(cols,3) title "rest of the solver", \
     '' using "share_set_rows" lc rgb word(cols,4) title "row selection", \
     '' using "share_outside" lc rgb word(cols,5) title "integrator outside the solver"

# ---- 7. growth with the problem size (friction chain, sparse model API) ----
f = dir."/growth.csv"
set output dir."/growth.png"
set terminal pngcairo size 800,600 font ",10"
unset multiplot
set autoscale
set xrange [5:2000]
set logscale xy
set format x "%g"
set format y "10^{%L}"
set key inside top left
set title "Friction chain: CPU time per step against n (growth.csv)"
set xlabel "n (masses = switching subsystems; n_x = 2n)"
set ylabel "ms per step"
plot f using (sel("series","default") ? column("n") : NaN):"ms_per_step" with linespoints lc rgb word(cols,1) pt 7 title "default (converged guess, few Newton iterations)", \
     f using (sel("series","newton") ? column("n") : NaN):"ms_per_step" with linespoints lc rgb word(cols,2) pt 5 title "one Newton iteration (KLU) every step", \
     f using (sel("series","default") ? column("n") : NaN):(0.0065 * column("n")) with lines lc black dt 2 title "linear"

# ---- work-precision: error-controlled FESD, fixed steps, CVODE ----
f = dir."/workprec.csv"
if (system("test -f ".f." && echo 1") eq "1") {
  set terminal pngcairo size 1600,520 font ",10"
  set output dir."/workprec.png"
  reset
  set datafile separator ","
  set grid
  set autoscale xy
  set format x "10^{%L}"
  set format y "10^{%L}"
  set logscale xy
  set xlabel "CPU time per integration [ms]"
  set ylabel "|x(T) - x^*(T)|"
  set key top right font ",8"
  meths = "fesd-adaptive fesd-fixed cvode-adams cvode-bdf"
  methname = "FESD-adaptive(rtol) FESD-fixed(N_{sim}) CVODE-Adams CVODE-BDF"
  set multiplot layout 1,4 title "Work-precision (workprec.csv): marker = stages s (FESD); CVODE: roots + restarts, sign-following RHS (fails on sliding problems)"
  do for [p in "oscillator sign-c slide-exit-2d stick-slip"] {
    set title p
    plot for [m=1:2] for [s=1:5] f using (sel("problem", p) && sel("method", word(meths,m)) && column("stages")==s && column("status")==0 ? column("cpu_ms") : NaN):(floor16(column("error"))) \
           with linespoints lc rgb word(cols,m) pt s ps 0.6 notitle, \
         for [m=3:4] f using (sel("problem", p) && sel("method", word(meths,m)) && column("status")==0 ? column("cpu_ms") : NaN):(floor16(column("error"))) \
           with linespoints lc rgb word(cols,m) pt 7 ps 0.6 notitle, \
         for [m=1:4] NaN with lines lc rgb word(cols,m) lw 2 title word(methname,m)
  }
  unset multiplot
}

# ---- direct optimal control: ocp_step_eq, terminal error of the re-simulated controls vs CPU ----
f = dir."/ocp_pareto.csv"
if (system("test -f ".f." && echo 1") eq "1") {
  set terminal pngcairo size 900,600 font ",10"
  set output dir."/ocp_pareto.png"
  reset
  set datafile separator ","
  set grid
  set logscale xy
  set format x "10^{%L}"
  set format y "10^{%L}"
  set xlabel "CPU time of the OCP solve [ms]"
  set ylabel "E(T) = |q_{sim}(4) - q_{final}|"
  set key bottom left font ",8"
  ofams = "radau lobatto3c gauss erk"
  ofamname = "Radau-IIA Lobatto-IIIC Gauss-Legendre explicit"
  set title "ocp\\_step\\_eq (N_{ctrl} = 6), converged: FESD filled (grey: presolve = 0), standard open (triangles: presolve = 0); size grows with s" font ",9"
  pre(p) = column("presolve") == p
  plot f using (sel("method","fesd") && pre(0) && sel("status","FESD_OK") ? column("cpu_ms") : NaN):(column("E")):(0.4+0.25*column("s")) \
         with points lc rgb "#b0b0b0" pt 7 ps variable title "FESD, presolve = 0", \
       for [a=1:4] f using (sel("method","fesd") && pre(1) && sel("family", word(ofams,a)) && sel("status","FESD_OK") ? column("cpu_ms") : NaN):(column("E")):(0.4+0.25*column("s")) \
         with points lc rgb word(cols,a) pt 7 ps variable title "FESD ".word(ofamname,a), \
       for [a=1:4] f using (sel("method","standard") && pre(1) && sel("family", word(ofams,a)) && sel("status","FESD_OK") ? column("cpu_ms") : NaN):(column("E")):(0.4+0.25*column("s")) \
         with points lc rgb word(cols,a) pt 6 ps variable title "standard ".word(ofamname,a), \
       for [a=1:4] f using (sel("method","standard") && pre(0) && sel("family", word(ofams,a)) && sel("status","FESD_OK") ? column("cpu_ms") : NaN):(column("E")):(0.4+0.25*column("s")) \
         with points lc rgb word(cols,a) pt 8 ps variable notitle
}
