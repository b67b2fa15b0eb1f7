/* fcm-sim --plot: the per-step log drawn against time (apps/fcm-sim-plot.c). */
#ifndef FCM_SIM_PLOT_H
#define FCM_SIM_PLOT_H

/** Draw the log `logpath` (<dir>/<name>_log.csv of fcm_simulation_write_log()) into
 * <dir>/<name>_log.png with gnuplot, through the script <dir>/<name>_log.gp kept beside it
 * (the plotted columns as a data block, one row per log row: `gnuplot <name>_log.gp` draws it
 * again): panels of the total energy (J), the linear momentum (kg m/s), the Newton iterations
 * and the reactions (N) of the first 8 fixed or motion effects, against time (s). 1 when
 * written, when gnuplot is missing or when the log has no row yet (each said on stderr), 0 on
 * an error (said on stderr). */
int sim_plot_log(const char *prog, const char *logpath);

#endif /* FCM_SIM_PLOT_H */
