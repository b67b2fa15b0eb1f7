/* apps: process environment of the fcm programs (not part of the library). */
#ifndef FCM_APP_ENV_H
#define FCM_APP_ENV_H

/** Make the program behave on shared machines; call it first in main().
 *
 * Idle OpenMP threads spin by default (libgomp: about 300,000 polls before sleeping at
 * every barrier), which costs little on idle cores but, when the cores are busy with
 * other work, burns the time slices the working threads need: a MINRES solve with many
 * short parallel regions ran 20-30x slower beside a load of 8 on 2 cores. The programs
 * therefore wait passively (OMP_WAIT_POLICY=passive: idle threads sleep at once).
 *
 * The OpenMP runtime reads its environment when it is loaded, before main(), so setting
 * the variable here would come too late (and a .preinit_array function cannot set it
 * either: glibc installs the environment after it). Instead, when the user has set none
 * of OMP_WAIT_POLICY, GOMP_SPINCOUNT and KMP_BLOCKTIME, this sets OMP_WAIT_POLICY=passive
 * and re-executes the program once (/proc/self/exe, same arguments, Linux only); the new
 * process finds the variable set and returns at once. Any of those variables set by the
 * user (e.g. OMP_WAIT_POLICY=active on dedicated cores) is left as it is. Nothing happens
 * under valgrind (its preload library in LD_PRELOAD: a re-executed child would escape the
 * tool), and when the re-execution fails the program continues with the runtime's
 * default policy. Returns only when no re-execution took place. */
void app_env_init(int argc, char **argv);

#endif /* FCM_APP_ENV_H */
