/* The peer for phong's benchmarks: the same scenes through OpenGL on Mesa's llvmpipe (OSMesa),
 * timed the same way as `phong bench` (one warm-up frame, then FRAMES frames, glFinish after
 * each). Gouraud uses OpenGL's fixed-function lighting; Phong a GLSL 1.20 shader evaluating
 * the same fixed-function equation per fragment, with the scene's light count compiled in (the
 * fastest form llvmpipe runs: a loop over a uniform count with `break` ran the 4-light fill
 * 1.7x slower). Not part of the product or of CI.
 *
 *   harness fill|sphere SEGMENTS gouraud|phong LIGHTS WIDTH HEIGHT FRAMES [out.ppm]
 *
 * With TEXTURE=file.ppm (a binary P6 PPM) in the environment, the object has that diffuse map,
 * repeated 4 x 3 times on the fill quad and 4 x 2 times round the sphere, mipmapped by the
 * driver (glGenerateMipmap), sampled GL_LINEAR_MIPMAP_LINEAR and applied as GL_MODULATE with a
 * separate specular colour (the fixed function's, or the same in the Phong shader): the
 * textured benchmark scenes' *_textured files.
 *
 * Build and run: see BENCHMARKS.md (benches/llvmpipe/run.sh).
 */
#define GL_GLEXT_PROTOTYPES
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/glu.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

/* The lights of benches/scenes: point lights with attenuation (1, 0.05, 0.02). */
static const float LPOS[8][3] = {{-2, 2, 3}, {2, 2, 3}, {-2, -2, 3}, {2, -2, 3},
                                 {0, 3, 2},  {0, -3, 2}, {3, 0, 2},  {-3, 0, 2}};
static const float LCOL[8][3] = {{1.0, 0.9, 0.8}, {0.6, 0.7, 1.0}, {0.9, 0.5, 0.5}, {0.5, 0.9, 0.6},
                                 {0.8, 0.8, 0.4}, {0.4, 0.8, 0.8}, {0.8, 0.4, 0.8}, {0.7, 0.7, 0.7}};

static const char *VS =
    "#version 120\n"
    "varying vec3 p; varying vec3 n;\n"
    "void main() { p = vec3(gl_ModelViewMatrix * gl_Vertex); n = gl_NormalMatrix * gl_Normal;\n"
    "  gl_Position = ftransform(); }\n";
/* OpenGL 2.1's lighting equation (spec 2.14.1) per fragment, local viewer, positional lights;
 * NLIGHTS is defined before it (see main). */
static const char *FS =
    "varying vec3 p; varying vec3 n;\n"
    "void main() {\n"
    "  vec3 N = normalize(n); vec3 V = normalize(-p);\n"
    "  vec3 c = gl_FrontMaterial.emission.rgb + gl_FrontMaterial.ambient.rgb * gl_LightModel.ambient.rgb;\n"
    "  for (int i = 0; i < NLIGHTS; i++) {\n"
    "    vec3 d = gl_LightSource[i].position.xyz - p; float dist = length(d); vec3 L = d / dist;\n"
    "    float att = 1.0 / (gl_LightSource[i].constantAttenuation + dist * (gl_LightSource[i].linearAttenuation\n"
    "                + dist * gl_LightSource[i].quadraticAttenuation));\n"
    "    float ndl = dot(N, L);\n"
    "    vec3 term = gl_FrontMaterial.ambient.rgb * gl_LightSource[i].ambient.rgb;\n"
    "    if (ndl > 0.0) {\n"
    "      term += ndl * gl_FrontMaterial.diffuse.rgb * gl_LightSource[i].diffuse.rgb;\n"
    "      float ndh = max(dot(N, normalize(L + V)), 0.0);\n"
    "      term += pow(ndh, gl_FrontMaterial.shininess) * gl_FrontMaterial.specular.rgb * gl_LightSource[i].specular.rgb;\n"
    "    }\n"
    "    c += att * term; }\n"
    "  gl_FragColor = vec4(clamp(c, 0.0, 1.0), 1.0);\n"
    "}\n";
/* The same with a diffuse map: the primary colour clamped, times the texel, plus the clamped
 * specular (GL_MODULATE with GL_SEPARATE_SPECULAR_COLOR). */
static const char *VS_TEX =
    "#version 120\n"
    "varying vec3 p; varying vec3 n;\n"
    "void main() { p = vec3(gl_ModelViewMatrix * gl_Vertex); n = gl_NormalMatrix * gl_Normal;\n"
    "  gl_TexCoord[0] = gl_MultiTexCoord0; gl_Position = ftransform(); }\n";
static const char *FS_TEX =
    "uniform sampler2D map; varying vec3 p; varying vec3 n;\n"
    "void main() {\n"
    "  vec3 N = normalize(n); vec3 V = normalize(-p);\n"
    "  vec3 c = gl_FrontMaterial.emission.rgb + gl_FrontMaterial.ambient.rgb * gl_LightModel.ambient.rgb;\n"
    "  vec3 s = vec3(0.0);\n"
    "  for (int i = 0; i < NLIGHTS; i++) {\n"
    "    vec3 d = gl_LightSource[i].position.xyz - p; float dist = length(d); vec3 L = d / dist;\n"
    "    float att = 1.0 / (gl_LightSource[i].constantAttenuation + dist * (gl_LightSource[i].linearAttenuation\n"
    "                + dist * gl_LightSource[i].quadraticAttenuation));\n"
    "    float ndl = dot(N, L);\n"
    "    c += att * gl_FrontMaterial.ambient.rgb * gl_LightSource[i].ambient.rgb;\n"
    "    if (ndl > 0.0) {\n"
    "      c += att * ndl * gl_FrontMaterial.diffuse.rgb * gl_LightSource[i].diffuse.rgb;\n"
    "      float ndh = max(dot(N, normalize(L + V)), 0.0);\n"
    "      s += att * pow(ndh, gl_FrontMaterial.shininess) * gl_FrontMaterial.specular.rgb * gl_LightSource[i].specular.rgb;\n"
    "    }\n"
    "  }\n"
    "  vec3 t = texture2D(map, gl_TexCoord[0].st).rgb;\n"
    "  gl_FragColor = vec4(clamp(clamp(c, 0.0, 1.0) * t + clamp(s, 0.0, 1.0), 0.0, 1.0), 1.0);\n"
    "}\n";

/* A binary P6 PPM as RGBA rows bottom first (OpenGL's order); NULL where it cannot be read. */
static unsigned char *read_ppm(const char *path, int *w, int *h) {
    FILE *f = fopen(path, "rb");
    int max;
    if (!f || fscanf(f, "P6 %d %d %d", w, h, &max) != 3 || max != 255 || fgetc(f) == EOF) return NULL;
    unsigned char *rgb = malloc((size_t)*w * *h * 3), *rgba = malloc((size_t)*w * *h * 4);
    if (fread(rgb, 3, (size_t)*w * *h, f) != (size_t)*w * *h) return NULL;
    fclose(f);
    for (int y = 0; y < *h; y++)
        for (int x = 0; x < *w; x++) {
            unsigned char *i = rgb + 3 * ((size_t)(*h - 1 - y) * *w + x), *o = rgba + 4 * ((size_t)y * *w + x);
            o[0] = i[0]; o[1] = i[1]; o[2] = i[2]; o[3] = 255;
        }
    free(rgb);
    return rgba;
}

static GLuint compile(GLenum kind, const char *src) {
    GLuint s = glCreateShader(kind);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096];
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        fprintf(stderr, "shader: %s\n", log);
        exit(1);
    }
    return s;
}

int main(int argc, char **argv) {
    if (argc < 8) {
        fprintf(stderr, "usage: %s fill|sphere SEGMENTS gouraud|phong LIGHTS WIDTH HEIGHT FRAMES [out.ppm]\n", argv[0]);
        return 2;
    }
    int sphere = strcmp(argv[1], "sphere") == 0, seg = atoi(argv[2]);
    int phong = strcmp(argv[3], "phong") == 0, nl = atoi(argv[4]);
    int w = atoi(argv[5]), h = atoi(argv[6]), frames = atoi(argv[7]);
    if (nl < 1 || nl > 8 || w < 1 || h < 1 || frames < 1) return 2;

    OSMesaContext ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, NULL);
    unsigned char *buf = malloc((size_t)w * h * 4);
    if (!ctx || !OSMesaMakeCurrent(ctx, buf, GL_UNSIGNED_BYTE, w, h)) {
        fprintf(stderr, "OSMesa context failed\n");
        return 1;
    }

    /* Geometry: phong's unit UV sphere (segments slices, segments/2 stacks, the same vertex
     * formula and triangles, pole triangles of zero area dropped), or the fill scene's quad. */
    int rows = sphere ? (seg / 2 > 2 ? seg / 2 : 2) : 1, cols = sphere ? seg : 1;
    int nv = (rows + 1) * (cols + 1);
    float *vtx = malloc(sizeof(float) * 6 * nv), *uv = malloc(sizeof(float) * 2 * nv);
    for (int i = 0; i <= rows; i++)
        for (int j = 0; j <= cols; j++) {
            float *o = vtx + 6 * (i * (cols + 1) + j);
            /* phong's coordinates for the shape, times the scene's uv_scale. */
            uv[2 * (i * (cols + 1) + j)] = (float)j / cols * 4.0f;
            uv[2 * (i * (cols + 1) + j) + 1] = (1.0f - (float)i / rows) * (sphere ? 2.0f : 3.0f);
            if (sphere) {
                float th = (float)i / rows * 3.14159265f, ph = (float)j / cols * 6.2831853f;
                o[0] = sinf(th) * cosf(ph); o[1] = cosf(th); o[2] = sinf(th) * sinf(ph);
                o[3] = o[0]; o[4] = o[1]; o[5] = o[2];
            } else {
                o[0] = j ? 3.0f : -3.0f; o[1] = i ? -2.0f : 2.0f; o[2] = 0;
                o[3] = 0; o[4] = 0; o[5] = 1;
            }
        }
    unsigned *idx = malloc(sizeof(unsigned) * 6 * rows * cols);
    int ni = 0;
    for (int i = 0; i < rows; i++)
        for (int j = 0; j < cols; j++) {
            unsigned a = i * (cols + 1) + j, b = a + 1, c = (i + 1) * (cols + 1) + j + 1, d = c - 1;
            unsigned t[2][3] = {{a, b, c}, {a, c, d}};
            for (int k = 0; k < 2; k++) {
                float *p = vtx + 6 * t[k][0], *q = vtx + 6 * t[k][1], *r = vtx + 6 * t[k][2];
                float u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, v[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
                float cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2], cz = u[0] * v[1] - u[1] * v[0];
                if (cx * cx + cy * cy + cz * cz < 1e-24f) continue;
                /* Wind counter-clockwise about the vertex normals, as phong does. */
                float nx = p[3] + q[3] + r[3], ny = p[4] + q[4] + r[4], nz = p[5] + q[5] + r[5];
                int flip = cx * nx + cy * ny + cz * nz < 0;
                idx[ni++] = t[k][0]; idx[ni++] = t[k][flip ? 2 : 1]; idx[ni++] = t[k][flip ? 1 : 2];
            }
        }
    GLuint vbo, ibo;
    glGenBuffers(1, &vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof(float) * 6 * nv, vtx, GL_STATIC_DRAW);
    glGenBuffers(1, &ibo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, sizeof(unsigned) * ni, idx, GL_STATIC_DRAW);
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_NORMAL_ARRAY);
    glVertexPointer(3, GL_FLOAT, 24, (void *)0);
    glNormalPointer(GL_FLOAT, 24, (void *)12);
    const char *texture = getenv("TEXTURE");
    if (texture) {
        int tw, th;
        unsigned char *texels = read_ppm(texture, &tw, &th);
        if (!texels) {
            fprintf(stderr, "cannot read %s (a binary P6 PPM)\n", texture);
            return 1;
        }
        GLuint uvb, tex;
        glGenBuffers(1, &uvb);
        glBindBuffer(GL_ARRAY_BUFFER, uvb);
        glBufferData(GL_ARRAY_BUFFER, sizeof(float) * 2 * nv, uv, GL_STATIC_DRAW);
        glEnableClientState(GL_TEXTURE_COORD_ARRAY);
        glTexCoordPointer(2, GL_FLOAT, 0, (void *)0);
        glBindBuffer(GL_ARRAY_BUFFER, vbo);
        glGenTextures(1, &tex);
        glBindTexture(GL_TEXTURE_2D, tex);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, tw, th, 0, GL_RGBA, GL_UNSIGNED_BYTE, texels);
        glGenerateMipmap(GL_TEXTURE_2D);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
        glLightModeli(GL_LIGHT_MODEL_COLOR_CONTROL, GL_SEPARATE_SPECULAR_COLOR);
        glEnable(GL_TEXTURE_2D);
    }

    glViewport(0, 0, w, h);
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    gluPerspective(45.0, (double)w / h, 0.1, 100.0);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    gluLookAt(0, 0, sphere ? 2.726 : 3.0, 0, 0, 0, 0, 1, 0);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glEnable(GL_CULL_FACE);
    glClearColor(0, 0, 0, 1);

    glEnable(GL_LIGHTING);
    glEnable(GL_NORMALIZE);
    glShadeModel(GL_SMOOTH);
    float amb[4] = {0.2f, 0.2f, 0.2f, 1};
    glLightModelfv(GL_LIGHT_MODEL_AMBIENT, amb);
    glLightModeli(GL_LIGHT_MODEL_LOCAL_VIEWER, GL_TRUE);
    for (int i = 0; i < nl; i++) {
        float pos[4] = {LPOS[i][0], LPOS[i][1], LPOS[i][2], 1}, c[4] = {LCOL[i][0], LCOL[i][1], LCOL[i][2], 1};
        float black[4] = {0, 0, 0, 1};
        glEnable(GL_LIGHT0 + i);
        glLightfv(GL_LIGHT0 + i, GL_POSITION, pos); /* in eye space of the look-at above */
        glLightfv(GL_LIGHT0 + i, GL_AMBIENT, black);
        glLightfv(GL_LIGHT0 + i, GL_DIFFUSE, c);
        glLightfv(GL_LIGHT0 + i, GL_SPECULAR, c);
        glLightf(GL_LIGHT0 + i, GL_CONSTANT_ATTENUATION, 1.0f);
        glLightf(GL_LIGHT0 + i, GL_LINEAR_ATTENUATION, 0.05f);
        glLightf(GL_LIGHT0 + i, GL_QUADRATIC_ATTENUATION, 0.02f);
    }
    /* gold (sphere) or polished silver (fill), from phong's materials table. */
    float gold[4][4] = {{0.24725f, 0.1995f, 0.0745f, 1}, {0.75164f, 0.60648f, 0.22648f, 1}, {0.628281f, 0.555802f, 0.366065f, 1}, {51.2f}};
    float silver[4][4] = {{0.23125f, 0.23125f, 0.23125f, 1}, {0.2775f, 0.2775f, 0.2775f, 1}, {0.773911f, 0.773911f, 0.773911f, 1}, {89.6f}};
    float (*m)[4] = sphere ? gold : silver;
    glMaterialfv(GL_FRONT, GL_AMBIENT, m[0]);
    glMaterialfv(GL_FRONT, GL_DIFFUSE, m[1]);
    glMaterialfv(GL_FRONT, GL_SPECULAR, m[2]);
    glMaterialf(GL_FRONT, GL_SHININESS, m[3][0] > 128 ? 128 : m[3][0]);

    if (phong) {
        GLuint prog = glCreateProgram();
        glAttachShader(prog, compile(GL_VERTEX_SHADER, texture ? VS_TEX : VS));
        char fs[8192];
        snprintf(fs, sizeof fs, "#version 120\n#define NLIGHTS %d\n%s", nl, texture ? FS_TEX : FS);
        glAttachShader(prog, compile(GL_FRAGMENT_SHADER, fs));
        glLinkProgram(prog);
        glUseProgram(prog);
    }

    double t0 = 0;
    for (int f = 0; f <= frames; f++) {
        if (f == 1) t0 = now();
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glDrawElements(GL_TRIANGLES, ni, GL_UNSIGNED_INT, 0);
        glFinish();
    }
    double per = (now() - t0) / frames;
    printf("llvmpipe: %dx%d tris=%d frames=%d ms_per_frame=%.1f mpix_per_s=%.1f\n", w, h, ni / 3, frames, per * 1e3,
           (double)w * h / per / 1e6);
    if (argc > 8) {
        FILE *o = fopen(argv[8], "wb");
        fprintf(o, "P6\n%d %d\n255\n", w, h);
        for (int y = h - 1; y >= 0; y--)
            for (int x = 0; x < w; x++) fwrite(buf + 4 * ((size_t)y * w + x), 1, 3, o);
        fclose(o);
    }
    if (glGetError() != GL_NO_ERROR) fprintf(stderr, "GL error\n");
    OSMesaDestroyContext(ctx);
    return 0;
}
