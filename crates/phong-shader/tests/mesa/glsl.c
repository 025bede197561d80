/* The exported GLSL pair run by Mesa's OpenGL (OSMesa, llvmpipe, a compatibility context):
 * the shaders, their uniforms and the meshes come on standard input, the RGBA pixels (rows
 * from the bottom) go to standard output. Input:
 *   w h / background r g b (0..1) / vertex shader (its length, a newline, its bytes) /
 *   fragment shader (likewise) / scene uniforms / object count, then per object: its
 *   uniforms, cull (0/1), flat (0/1), vertex count, index count, positions, normals,
 *   centroids (flat only), indices.
 * Uniforms: a count, then per uniform `name kind count values...` (kind f: floats, v: vec3s,
 * m: mat4s, column-major). */
#define GL_GLEXT_PROTOTYPES
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void die(const char *what) { fprintf(stderr, "glsl: %s\n", what); exit(2); }
static int rdi(void) { int x; if (scanf("%d", &x) != 1) die("bad input"); return x; }
static float rdf(void) { float x; if (scanf("%f", &x) != 1) die("bad input"); return x; }

static char *rdsrc(void) {
    int n = rdi();
    getchar();
    char *s = malloc((size_t)n + 1);
    if (fread(s, 1, (size_t)n, stdin) != (size_t)n) die("short shader");
    s[n] = 0;
    return s;
}

static GLuint compile(GLenum kind, const char *src) {
    GLuint s = glCreateShader(kind);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[8192];
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        fprintf(stderr, "glsl: compile: %s\n", log);
        exit(1);
    }
    return s;
}

static void uniforms(GLuint prog) {
    int n = rdi();
    for (int u = 0; u < n; u++) {
        char name[128], kind[4];
        if (scanf("%127s %3s", name, kind) != 2) die("bad uniform");
        int count = rdi();
        int per = kind[0] == 'f' ? 1 : kind[0] == 'v' ? 3 : 16;
        float *v = malloc(sizeof(float) * (size_t)(count * per + 1));
        for (int i = 0; i < count * per; i++) v[i] = rdf();
        GLint at = glGetUniformLocation(prog, name);
        if (at >= 0 && count > 0) {
            if (per == 1) glUniform1fv(at, count, v);
            else if (per == 3) glUniform3fv(at, count, v);
            else glUniformMatrix4fv(at, count, GL_FALSE, v);
        }
        free(v);
    }
}

static float *rdfloats(int n) {
    float *v = malloc(sizeof(float) * (size_t)(n + 1));
    for (int i = 0; i < n; i++) v[i] = rdf();
    return v;
}

int main(void) {
    int w = rdi(), h = rdi();
    float bg[3] = {rdf(), rdf(), rdf()};
    char *vs = rdsrc(), *fs = rdsrc();
    OSMesaContext ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, NULL);
    unsigned char *buf = calloc((size_t)w * h, 4);
    if (!ctx || !OSMesaMakeCurrent(ctx, buf, GL_UNSIGNED_BYTE, w, h)) die("no OSMesa context");
    GLuint prog = glCreateProgram();
    glAttachShader(prog, compile(GL_VERTEX_SHADER, vs));
    glAttachShader(prog, compile(GL_FRAGMENT_SHADER, fs));
    glBindAttribLocation(prog, 0, "position");
    glBindAttribLocation(prog, 1, "normal");
    glBindAttribLocation(prog, 2, "triangleCentroid");
    glLinkProgram(prog);
    GLint ok;
    glGetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[8192];
        glGetProgramInfoLog(prog, sizeof log, NULL, log);
        fprintf(stderr, "glsl: link: %s\n", log);
        return 1;
    }
    glUseProgram(prog);
    uniforms(prog);
    glViewport(0, 0, w, h);
    glClearColor(bg[0], bg[1], bg[2], 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    int objects = rdi();
    for (int o = 0; o < objects; o++) {
        uniforms(prog);
        int cull = rdi(), flat = rdi(), nv = rdi(), ni = rdi();
        float *p = rdfloats(nv * 3), *n = rdfloats(nv * 3), *c = flat ? rdfloats(nv * 3) : NULL;
        GLuint *idx = malloc(sizeof(GLuint) * (size_t)(ni + 1));
        for (int i = 0; i < ni; i++) idx[i] = (GLuint)rdi();
        if (cull) glEnable(GL_CULL_FACE); else glDisable(GL_CULL_FACE);
        glEnableVertexAttribArray(0);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, p);
        glEnableVertexAttribArray(1);
        glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, n);
        if (flat) {
            glEnableVertexAttribArray(2);
            glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, 0, c);
        } else {
            glDisableVertexAttribArray(2);
        }
        glDrawElements(GL_TRIANGLES, ni, GL_UNSIGNED_INT, idx);
        free(p); free(n); free(c); free(idx);
    }
    glFinish();
    fwrite(buf, 4, (size_t)w * h, stdout);
    OSMesaDestroyContext(ctx);
    return 0;
}
