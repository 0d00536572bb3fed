/* SPDX-License-Identifier: MIT
 * A main() for the fuzz targets without libFuzzer: runs LLVMFuzzerTestOneInput once on every file
 * given (or every file of every folder given). ctest uses it to replay the committed corpora
 * (seeds and the regression inputs of issue 11) in the ordinary gcc build. */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerInitialize(int* argc, char*** argv);
int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static int run_file(const char* path)
{
    FILE* f = fopen(path, "rb");
    if (!f) { fprintf(stderr, "replay: cannot open %s\n", path); return 1; }
    size_t cap = 1 << 16, n = 0;
    uint8_t* buf = malloc(cap);
    size_t got;
    while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) buf = realloc(buf, cap *= 2);
    }
    fclose(f);
    if (!buf) return 1;
    LLVMFuzzerTestOneInput(buf, n);
    free(buf);
    return 0;
}

int main(int argc, char** argv)
{
    LLVMFuzzerInitialize(&argc, &argv);
    int files = 0, bad = 0;
    for (int i = 1; i < argc; ++i) {
        struct stat sb;
        if (stat(argv[i], &sb) != 0) { fprintf(stderr, "replay: no such path %s\n", argv[i]); return 1; }
        if (!S_ISDIR(sb.st_mode)) { bad |= run_file(argv[i]); ++files; continue; }
        DIR* d = opendir(argv[i]);
        if (!d) return 1;
        struct dirent* e;
        while ((e = readdir(d))) {
            if (e->d_name[0] == '.') continue;
            char path[4096];
            snprintf(path, sizeof path, "%s/%s", argv[i], e->d_name);
            bad |= run_file(path);
            ++files;
        }
        closedir(d);
    }
    printf("replay: %d inputs\n", files);
    return bad || files == 0;
}
