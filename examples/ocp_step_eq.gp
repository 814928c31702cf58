# Plots of examples/ocp_step_eq (paper figures step_eq_solution, step_eq_controls,
# step_eq_step_size): gnuplot -e "dir='OUTDIR'" examples/ocp_step_eq.gp
# reads ocp_step_eq_{traj,elements,events}.csv, writes ocp_step_eq_{solution,controls,step_size}.png
if (!exists("dir")) dir = "."
set datafile separator ","
set terminal pngcairo size 1200,450 font ",10"
set grid
traj = dir."/ocp_step_eq_traj.csv"
ev = dir."/ocp_step_eq_events.csv"
el = dir."/ocp_step_eq_elements.csv"
T = 4.0; N = 6

# ---- trajectory in the q plane with the switching surfaces, and q(t) ----
set output dir."/ocp_step_eq_solution.png"
set multiplot layout 1,2 title "ocp\\_step\\_eq: optimal trajectory (FESD)"
set title "q plane"
set xlabel "q_1"; set ylabel "q_2"
set size ratio -1
set parametric
set trange [-1.5:2.2]
set xrange [-1:2.3]; set yrange [-1.2:1.2]
set key bottom right font ",9"
plot -0.15*t*t, t w l lc rgb "#999999" dt 2 title "c_1 = q_1 + 0.15 q_2^2 = 0", \
     t, 0.05*t*t*t w l lc rgb "#555555" dt 4 title "c_2 = -0.05 q_1^3 + q_2 = 0", \
     traj using "q1":"q2" w l lw 2 lc rgb "#1f77b4" title "q(t)", \
     '+' using (2*pi/3):(pi/3) every ::0::0 w p pt 7 ps 1.2 lc rgb "#2ca02c" title "q(0)", \
     '+' using (-pi/6):(-pi/4) every ::0::0 w p pt 9 ps 1.5 lc rgb "#d62728" title "q_{final}"
unset parametric
set size noratio
set autoscale xy
set title "q(t); vertical lines: events"
set xlabel "t"; set ylabel "q"
set xrange [0:T]; set yrange [-1:2.5]
set key top right
plot traj using "t":"q1" w l lw 2 title "q_1", traj using "t":"q2" w l lw 2 title "q_2", \
     ev using 1:(-1):(0):(3.5) w vectors nohead dt 3 lc rgb "#888888" notitle
unset multiplot

# ---- v(t) and the piecewise constant controls u(t) ----
set output dir."/ocp_step_eq_controls.png"
set multiplot layout 1,2 title "ocp\\_step\\_eq: states v and controls u (dashed: control grid)"
set title "v(t)"; set ylabel "v"
set yrange [-2.2:2.2]
set for [k=1:N-1] arrow from k*T/N, graph 0 to k*T/N, graph 1 nohead dt 2 lc rgb "#aaaaaa"
plot traj using "t":"v1" w l lw 2 title "v_1", traj using "t":"v2" w l lw 2 title "v_2", \
     2 w l dt 3 lc rgb "black" title "|v| <= 2", -2 w l dt 3 lc rgb "black" notitle
set title "u(t)"; set ylabel "u"
set autoscale y
plot traj using "t":"u1" w steps lw 2 title "u_1", traj using "t":"u2" w steps lw 2 title "u_2"
unset arrow
unset multiplot

# ---- element lengths h_{k,n} ----
set output dir."/ocp_step_eq_step_size.png"
set terminal pngcairo size 800,400 font ",10"
set title "element lengths h_{k,n} (step equilibration: equal between switches)"
set xlabel "element start time t"; set ylabel "h"
set autoscale xy
set xrange [0:T]; set yrange [0:*]
set for [k=1:N-1] arrow from k*T/N, graph 0 to k*T/N, graph 1 nohead dt 2 lc rgb "#aaaaaa"
plot el using "t":"h" w p pt 7 ps 0.9 lc rgb "#1f77b4" title "h_{k,n}", \
     el using "t":"h" w steps lc rgb "#1f77b4" notitle, \
     ev using 1:(0):(0):(0.2) w vectors nohead dt 3 lc rgb "#d62728" title "events"
