#include "video.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "io.h"
#include "log.h"

struct sb_video {
    char path[4096], temp[4200];
    uint32_t width, height;
    pid_t child;
    int pipe_fd;
    bool failed;
    struct sigaction old_sigpipe;
};

bool sb_video_encoder_found(void)
{
    const char *path = getenv("PATH");
    if (!path)
        return false;
    for (const char *p = path; *p;) {
        const char *end = strchr(p, ':');
        size_t n = end ? (size_t)(end - p) : strlen(p);
        char candidate[4200];
        if (n && n < 4096) {
            snprintf(candidate, sizeof(candidate), "%.*s/ffmpeg", (int)n, p);
            struct stat st;
            if (stat(candidate, &st) == 0 && S_ISREG(st.st_mode) && access(candidate, X_OK) == 0)
                return true;
        }
        p += n + (end != NULL);
        if (!end)
            break;
    }
    return false;
}

enum sb_result sb_video_create(const char *path, uint32_t width, uint32_t height, double fps, struct sb_video **video)
{
    *video = NULL;
    struct sb_video *v = calloc(1, sizeof(*v));
    if (!v)
        return SB_ERR_NOMEM;
    v->width = width;
    v->height = height;
    v->pipe_fd = -1;
    snprintf(v->path, sizeof(v->path), "%s", path);
    /* Beside the target, so the rename stays on one file system. */
    snprintf(v->temp, sizeof(v->temp), "%s.partial", path);
    char size[32], rate[32];
    snprintf(size, sizeof(size), "%ux%u", width, height);
    snprintf(rate, sizeof(rate), "%.6g", fps);
    const char *argv[] = {"ffmpeg", "-hide_banner", "-nostats", "-loglevel", "error", "-y", "-f", "rawvideo",
                          "-pix_fmt", "rgba", "-s", size, "-r", rate, "-i", "pipe:0", "-an",
                          /* Even sizes for 4:2:0: pad the odd row or column. */
                          "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2,scale=out_color_matrix=bt709:out_range=tv", "-c:v",
                          "libx264", "-preset", "medium", "-crf", "18", "-pix_fmt", "yuv420p",
                          /* Say what it is: Rec.709 primaries and matrix, the sRGB curve, video range. */
                          "-colorspace", "bt709", "-color_primaries", "bt709", "-color_trc", "iec61966-2-1",
                          "-color_range", "tv", "-movflags", "+faststart", "-f", "mp4", v->temp, NULL};
    int fds[2];
    if (pipe(fds) != 0) {
        sb_error("%s: cannot start ffmpeg: pipe: %s", path, strerror(errno));
        free(v);
        return SB_ERR_IO;
    }
    pid_t child = fork();
    if (child < 0) {
        sb_error("%s: cannot start ffmpeg: fork: %s", path, strerror(errno));
        close(fds[0]);
        close(fds[1]);
        free(v);
        return SB_ERR_IO;
    }
    if (child == 0) {
        dup2(fds[0], STDIN_FILENO);
        close(fds[0]);
        close(fds[1]);
        execvp("ffmpeg", (char *const *)argv);
        _exit(127);
    }
    close(fds[0]);
    v->child = child;
    v->pipe_fd = fds[1];
    /* If ffmpeg dies, a write gets EPIPE (an error to report), not SIGPIPE. */
    struct sigaction ignore = {.sa_handler = SIG_IGN};
    sigemptyset(&ignore.sa_mask);
    sigaction(SIGPIPE, &ignore, &v->old_sigpipe);
    *video = v;
    return SB_OK;
}

enum sb_result sb_video_write(struct sb_video *v, const uint8_t *rgba)
{
    if (v->failed)
        return SB_ERR_IO;
    if (!sb_write_all(v->pipe_fd, rgba, (size_t)v->width * v->height * 4)) {
        sb_error("%s: ffmpeg stopped taking frames: %s", v->path, strerror(errno));
        v->failed = true;
        return SB_ERR_IO;
    }
    return SB_OK;
}

enum sb_result sb_video_destroy(struct sb_video **video, bool keep)
{
    struct sb_video *v = *video;
    if (!v)
        return SB_OK;
    *video = NULL;
    close(v->pipe_fd);
    int status = 0;
    while (waitpid(v->child, &status, 0) < 0 && errno == EINTR)
        ;
    sigaction(SIGPIPE, &v->old_sigpipe, NULL);
    enum sb_result res = v->failed ? SB_ERR_IO : SB_OK;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        if (keep)
            sb_error("%s: ffmpeg failed (%s %d)%s", v->path, WIFEXITED(status) ? "exit" : "signal",
                     WIFEXITED(status) ? WEXITSTATUS(status) : WTERMSIG(status),
                     WIFEXITED(status) && WEXITSTATUS(status) == 127 ? ": not installed (apt-get install ffmpeg)" : "");
        res = SB_ERR_IO;
    }
    if (keep && !res && rename(v->temp, v->path) != 0) {
        sb_error("%s: cannot rename %s into place: %s", v->path, v->temp, strerror(errno));
        res = SB_ERR_IO;
    }
    if (!keep || res)
        unlink(v->temp);
    free(v);
    return keep ? res : SB_OK;
}
