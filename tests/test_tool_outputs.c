/* SPDX-License-Identifier: BSD-3-Clause */
/* The rule every program follows for its outputs (tools/common/tool_outputs.h): a run's
 * outputs are a set, all of them or none. A failed run removes what it wrote; a signal before
 * the set is complete removes it and ends the run as killed by the signal; a signal after it is
 * complete leaves it and ends the run normally (exit 0). The signal cases run in a child
 * process, which the rule may end. */
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check.h"
#include "tool_common.h"

static char dir[4000];

static const char *path_of(const char *name)
{
    static char paths[4][4096 + 64];
    static int next;
    char *p = paths[next++ % 4];
    snprintf(p, sizeof paths[0], "%s/%s", dir, name);
    return p;
}

static void make(const char *name)
{
    FILE *f = fopen(path_of(name), "w");
    REQUIRE(f != NULL);
    fputs("whole\n", f);
    fclose(f);
}

static int exists(const char *name)
{
    struct stat st;
    return stat(path_of(name), &st) == 0;
}

static void check_failed_run(void)
{
    tool_outputs o = {0};
    make("a");
    make("b");
    make("other");
    REQUIRE(tool_outputs_add(&o, path_of("a")) == 0);
    REQUIRE(tool_outputs_add(&o, path_of("b")) == 0);
    REQUIRE(tool_outputs_add(&o, "-") == 0); /* standard output: not a file, not recorded */
    CHECK(o.count == 2);
    CHECK(tool_outputs_end(&o, "test", "x", 1) == 1);
    CHECK(!exists("a"));
    CHECK(!exists("b"));
    CHECK(exists("other")); /* not the run's */
}

static void check_complete_run(void)
{
    tool_outputs o = {0};
    make("a");
    REQUIRE(tool_outputs_add(&o, path_of("a")) == 0);
    tool_outputs_complete(&o);
    CHECK(tool_outputs_end(&o, "test", "x", 0) == 0);
    CHECK(exists("a"));
}

static void check_made_folder(void)
{
    tool_outputs o = {0};
    REQUIRE(mkdir(path_of("frames"), 0777) == 0);
    REQUIRE(tool_outputs_made_folder(&o, path_of("frames")) == 0);
    make("frames/f0");
    REQUIRE(tool_outputs_add(&o, path_of("frames/f0")) == 0);
    CHECK(tool_outputs_discard(&o) == 1);
    CHECK(!exists("frames")); /* made by the run and empty again: removed */
    REQUIRE(tool_outputs_end(&o, "test", "x", 1) == 1);
    tool_outputs p = {0};
    REQUIRE(mkdir(path_of("kept"), 0777) == 0);
    REQUIRE(tool_outputs_made_folder(&p, path_of("kept")) == 0);
    make("kept/f0");
    make("kept/someone_elses");
    REQUIRE(tool_outputs_add(&p, path_of("kept/f0")) == 0);
    CHECK(tool_outputs_end(&p, "test", "x", 1) == 1);
    CHECK(!exists("kept/f0"));
    CHECK(exists("kept/someone_elses")); /* a folder holding other files stays */
}

/* Runs a child that records outputs, takes `sig` before (complete == 0) or after the set is
 * complete, and ends by the rule; returns its wait status. */
static int child_run(int sig, int complete)
{
    fflush(NULL);
    pid_t pid = fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
        tool_signals_catch();
        tool_outputs o = {0};
        make("c1");
        make("c2");
        if (tool_outputs_add(&o, path_of("c1")) != 0 || tool_outputs_add(&o, path_of("c2")) != 0)
            _exit(99);
        if (complete)
            tool_outputs_complete(&o);
        raise(sig); /* recorded by the handler: the run goes on to its end */
        _exit(tool_outputs_end(&o, "test", "run", 0));
    }
    int status = 0;
    REQUIRE(waitpid(pid, &status, 0) == pid);
    return status;
}

static void check_signal_before_complete(void)
{
    int status = child_run(SIGINT, 0);
    CHECK(WIFSIGNALED(status));
    CHECK_MSG(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT, "status %d", status);
    CHECK(!exists("c1"));
    CHECK(!exists("c2"));
    status = child_run(SIGTERM, 0);
    CHECK_MSG(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM, "status %d", status);
    CHECK(!exists("c1"));
}

static void check_signal_after_complete(void)
{
    int status = child_run(SIGTERM, 1);
    CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0, "status %d", status);
    CHECK(exists("c1"));
    CHECK(exists("c2"));
}

static void make_scratch_dir(void)
{
    snprintf(dir, sizeof dir, "%s", test_tmp_dir("test_tool_outputs"));
}

int main(int argc, char **argv)
{
    static const test_case cases[] = {
        TEST_CASE(check_failed_run), TEST_CASE(check_complete_run), TEST_CASE(check_made_folder),
        TEST_CASE(check_signal_before_complete), TEST_CASE(check_signal_after_complete)};
    return RUN_CASES_WITH(argc, argv, cases, "test_tool_outputs", make_scratch_dir, NULL);
}
