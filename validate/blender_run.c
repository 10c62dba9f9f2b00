/* Blender process runner (validate/blender_run.h). */
#include "validate/blender_run.h"

#include <errno.h>
#include <fcntl.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "core/fileio.h"

extern char **environ;

const char *iris_blender_executable(const char *exe) {
  if (exe && exe[0]) return exe;
  const char *env = getenv("IRIS_BLENDER");
  return env && env[0] ? env : "blender";
}

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Appends `word` to the command line, single-quoted when it needs quoting. */
static void append_word(char *buf, size_t size, const char *word) {
  size_t len = strlen(buf);
  bool plain = word[0] != 0 && strspn(word, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                            "0123456789-_./=:+,") == strlen(word);
  char tmp[1100];
  if (plain)
    snprintf(tmp, sizeof tmp, "%s%s", len ? " " : "", word);
  else {
    size_t k = 0;
    if (len) tmp[k++] = ' ';
    tmp[k++] = '\'';
    for (const char *p = word; *p && k + 6 < sizeof tmp; p++) {
      if (*p == '\'') {
        memcpy(tmp + k, "'\\''", 4);
        k += 4;
      } else
        tmp[k++] = *p;
    }
    tmp[k++] = '\'';
    tmp[k] = 0;
  }
  if (len + strlen(tmp) + 1 < size) memcpy(buf + len, tmp, strlen(tmp) + 1);
}

static void parse_log(const char *log_path, iris_blender_run_info *info) {
  char *text = NULL;
  size_t size = 0;
  if (iris_file_read(log_path, 64u << 20, &text, &size, NULL) != IRIS_OK) return;
  /* Blender's banner: "Blender 3.4.1" on the first lines. */
  const char *b = strstr(text, "Blender ");
  if (b) sscanf(b + 8, "%63[0-9.]", info->version);
  const char *line = strstr(text, "IRIS_BLENDER ");
  if (line) {
    const char *p = strstr(line, "build_seconds=");
    if (p) info->build_seconds = strtod(p + 14, NULL);
    p = strstr(line, "render_seconds=");
    if (p) info->render_seconds = strtod(p + 15, NULL);
  }
  free(text);
}

iris_status iris_blender_run(const char *exe, const char *script, const char *const *args,
                             const char *log_path, iris_blender_run_info *info, iris_error *err) {
  memset(info, 0, sizeof *info);
  info->build_seconds = info->render_seconds = -1.0;
  exe = iris_blender_executable(exe);
  const char *argv[64];
  int n = 0;
  argv[n++] = exe;
  argv[n++] = "-b";
  argv[n++] = "--factory-startup";
  argv[n++] = "--python-exit-code";
  argv[n++] = "1";
  argv[n++] = "-P";
  argv[n++] = script;
  argv[n++] = "--";
  for (int i = 0; args && args[i] && n < 63; i++) argv[n++] = args[i];
  argv[n] = NULL;
  for (int i = 0; i < n; i++) append_word(info->command, sizeof info->command, argv[i]);

  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addclose(&fa, STDIN_FILENO);
  pid_t pid;
  double t0 = now_seconds();
  int rc = posix_spawnp(&pid, exe, &fa, NULL, (char *const *)argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0)
    return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL,
                          "cannot run Blender '%s': %s (install Debian's blender package or set "
                          "IRIS_BLENDER)", exe, strerror(rc));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR)
      return iris_error_set(err, IRIS_ERR_INTERNAL, NULL, 0, NULL, "waiting for Blender: %s",
                            strerror(errno));
  }
  info->wall_seconds = now_seconds() - t0;
  parse_log(log_path, info);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    /* exit 127 from the spawned child: the executable was not found */
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127)
      return iris_error_set(err, IRIS_ERR_USAGE, NULL, 0, NULL,
                            "cannot run Blender '%s' (install Debian's blender package or set "
                            "IRIS_BLENDER)", exe);
    return iris_error_set(err, IRIS_ERR_INTERNAL, log_path, 0, NULL,
                          "Blender failed (%s %d); see this log", WIFEXITED(status) ? "exit" : "signal",
                          WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status));
  }
  return IRIS_OK;
}
