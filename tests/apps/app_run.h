/* Running a program from an app test: the exit status of a shell command and whether a path
 * exists (the program's output, or its absence after a refused run). */
#ifndef FCM_TEST_APP_RUN_H
#define FCM_TEST_APP_RUN_H

#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>

/* The exit status of `cmd` run by the shell; -1 when it did not exit normally. */
static inline int app_run(const char *cmd)
{
  const int st = system(cmd);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* 1 when `path` names an existing file or directory. */
static inline int app_exists(const char *path)
{
  struct stat sb;
  return stat(path, &sb) == 0;
}

#endif
