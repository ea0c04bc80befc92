# Error against CPU seconds of the methods scripts/bench_peers.sh ran (Surge's in blue, SPlisHSPlasH's in red):
#   gnuplot -e "csv='out/bench_peers/methods.csv'; png='out/bench_peers/methods_error_vs_cpu.png'" scripts/plot_methods.gp
set terminal pngcairo size 820,460 noenhanced font ",11"
set output png
set datafile separator ","
set logscale x
set xrange [10:1600]
set yrange [0.02:0.06]
set xlabel "CPU seconds for 1 s of the dam break (2 cores, one run at a time)"
set ylabel "average density error, %"
set grid
set key off
surge(name) = strstrt(name, "Surge") == 1
plot csv every ::1 using ($2):(surge(strcol(1)) ? $4 : 1/0) with points pointtype 7 pointsize 1.6 lc rgb "#1f5fbf", \
     csv every ::1 using ($2):(surge(strcol(1)) ? 1/0 : $4) with points pointtype 5 pointsize 1.5 lc rgb "#c03020", \
     csv every ::1 using 2:4:1 with labels center offset char 0,1.1
