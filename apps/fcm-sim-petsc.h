/* fcm-sim --backend petsc: a scene run on the PETSc + MPI backend (fcm/scene_petsc.h), built when
 * the library has it (FCM_HAVE_PETSC). */
#ifndef FCM_SIM_PETSC_H
#define FCM_SIM_PETSC_H

/* Run the scene `path` (NULL: the built-in scene) on the processes of MPI_COMM_WORLD; steps > 0
 * caps the steps; check: at most 3 steps, no output; quiet: errors only; plot: the log drawn at
 * the end (sim_plot_log(), rank 0); checkpoint_every > 0:
 * <name>_checkpoint_NNNNNN.fcmck every that many steps (-1: the scene's interval); resume: a
 * checkpoint to continue from (NULL: none; the serial format, or a .fcmpk of earlier versions).
 * petsc_argc/argv: the program name and the PETSc options of the command line (-ksp_type ...).
 * Returns the exit code (0 ok, 1 run failed, 2 bad input), the same on every process. */
int sim_petsc_run(const char *path, const char *outdir, long long steps, int check, int quiet,
                  int plot, int checkpoint_every, const char *resume, int petsc_argc,
                  char **petsc_argv);

/* The summary's output line: every series of <dir>/<name> the run has written (the background
 * and surface PVD indexes, the log at `logpath`, with `plot` the log's picture
 * <name>_log.png), as "  output    a, b, c"; `no_frame`: the run wrote no new frame (said after
 * the log). */
void sim_print_output(const char *dir, const char *name, const char *logpath, int no_frame,
                      int plot);

#endif
