/* OpenGL 2.1 fixed-function lighting on Mesa (OSMesa, llvmpipe), driven by a scene that
 * phong-raster's tests write to stdin; writes the image (RGB, top row first) to stdout.
 * The reference that phong's `opengl` model is checked against (tests/mesa.rs).
 *
 * per_fragment = 1 draws with a GLSL 1.20 program that evaluates the same equation per
 * fragment from the fixed-function state (gl_LightSource, gl_FrontMaterial, gl_LightModel):
 * the equation of the OpenGL 2.1 specification (2.14.1) as Mesa's fixed-function vertex
 * program computes it (the specular term only where N·L > 0), with the interpolated normal
 * normalised per fragment.
 *
 * Input, whitespace-separated:
 *   W H  local_viewer two_sided per_fragment
 *   projection[16] view[16]          (column-major, as glLoadMatrixf)
 *   global_ambient[3]
 *   material: ambient[3] diffuse[3] specular[3] emission[3] shininess
 *   NLIGHTS, then per light: position[4] (world; w = 0: direction towards the light)
 *     ambient[3] diffuse[3] specular[3] k0 k1 k2 spot_direction[3] cutoff exponent
 *   NVERTS, then per vertex: position[3] normal[3] uv[2]
 *   NTRIS, then per triangle: 3 indices
 *   TW TH (0 0: no texture), then TW*TH RGBA texels (bytes, bottom row first), wrap (0 repeat,
 *   1 clamp to edge, 2 mirrored repeat), filter (0 GL_LINEAR_MIPMAP_LINEAR, 1 GL_LINEAR,
 *   2 GL_NEAREST); a texture is applied with GL_MODULATE and GL_SEPARATE_SPECULAR_COLOR, its
 *   mipmaps built by the driver (glGenerateMipmap).
 */
#define GL_GLEXT_PROTOTYPES
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <stdio.h>
#include <stdlib.h>

static const char *VS =
    "#version 120\n"
    "varying vec3 p; varying vec3 n;\n"
    "void main() { p = vec3(gl_ModelViewMatrix * gl_Vertex); n = gl_NormalMatrix * gl_Normal;\n"
    "  gl_TexCoord[0] = gl_MultiTexCoord0; gl_Position = ftransform(); }\n";
static const char *FS =
    "#version 120\n"
    "uniform int nlights; uniform int textured; uniform int local; uniform sampler2D map;\n"
    "varying vec3 p; varying vec3 n;\n"
    "void main() {\n"
    "  vec3 N = normalize(n);\n"
    "  if (!gl_FrontFacing) N = -N;\n"
    "  vec3 V = local != 0 ? normalize(-p) : vec3(0.0, 0.0, 1.0);\n"
    "  vec3 c = gl_FrontMaterial.emission.rgb + gl_FrontMaterial.ambient.rgb * gl_LightModel.ambient.rgb;\n"
    "  vec3 s = vec3(0.0);\n"
    "  for (int i = 0; i < 8; i++) {\n"
    "    if (i >= nlights) break;\n"
    "    vec4 lp = gl_LightSource[i].position; vec3 L; float att = 1.0;\n"
    "    if (lp.w != 0.0) {\n"
    "      vec3 d = lp.xyz / lp.w - p; float dist = length(d); L = d / dist;\n"
    "      att = 1.0 / (gl_LightSource[i].constantAttenuation + dist * (gl_LightSource[i].linearAttenuation\n"
    "            + dist * gl_LightSource[i].quadraticAttenuation));\n"
    "    } else L = normalize(lp.xyz);\n"
    "    if (gl_LightSource[i].spotCutoff != 180.0) {\n"
    "      float sd = dot(-L, normalize(gl_LightSource[i].spotDirection));\n"
    "      att *= sd >= gl_LightSource[i].spotCosCutoff ? pow(max(sd, 0.0), gl_LightSource[i].spotExponent) : 0.0;\n"
    "    }\n"
    "    float ndl = dot(N, L);\n"
    "    c += att * gl_FrontMaterial.ambient.rgb * gl_LightSource[i].ambient.rgb;\n"
    "    if (ndl > 0.0) {\n"
    "      c += att * ndl * gl_FrontMaterial.diffuse.rgb * gl_LightSource[i].diffuse.rgb;\n"
    "      float ndh = max(dot(N, normalize(L + V)), 0.0);\n"
    "      s += att * pow(ndh, gl_FrontMaterial.shininess) * gl_FrontMaterial.specular.rgb * gl_LightSource[i].specular.rgb;\n"
    "    }\n"
    "  }\n"
    "  if (textured != 0)\n"
    "    gl_FragColor = vec4(clamp(clamp(c, 0.0, 1.0) * texture2D(map, gl_TexCoord[0].st).rgb + clamp(s, 0.0, 1.0), 0.0, 1.0), 1.0);\n"
    "  else\n"
    "    gl_FragColor = vec4(clamp(c + s, 0.0, 1.0), 1.0);\n"
    "}\n";

static GLuint compile(GLenum kind, const char *src) {
    GLuint s = glCreateShader(kind);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096];
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        fprintf(stderr, "ffp: shader: %s\n", log);
        exit(1);
    }
    return s;
}

static float rd(void) {
    float x;
    if (scanf("%f", &x) != 1) { fprintf(stderr, "ffp: bad input\n"); exit(2); }
    return x;
}
static void rdv(float *v, int n) { for (int i = 0; i < n; i++) v[i] = rd(); }

int main(void) {
    int w = (int)rd(), h = (int)rd(), local = (int)rd(), two = (int)rd(), per_fragment = (int)rd();
    float proj[16], view[16], amb[4] = {0, 0, 0, 1};
    rdv(proj, 16); rdv(view, 16); rdv(amb, 3);
    float ma[4] = {0, 0, 0, 1}, md[4] = {0, 0, 0, 1}, ms[4] = {0, 0, 0, 1}, me[4] = {0, 0, 0, 1};
    rdv(ma, 3); rdv(md, 3); rdv(ms, 3); rdv(me, 3);
    float shin = rd();

    OSMesaContext ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, NULL);
    unsigned char *buf = calloc((size_t)w * h, 4);
    if (!ctx || !OSMesaMakeCurrent(ctx, buf, GL_UNSIGNED_BYTE, w, h)) { fprintf(stderr, "ffp: no OSMesa context\n"); return 1; }
    glViewport(0, 0, w, h);
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixf(proj);
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixf(view); /* lights are given in world space: transformed by the view, as OpenGL does */
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    if (!two) glEnable(GL_CULL_FACE);
    glEnable(GL_LIGHTING);
    glEnable(GL_NORMALIZE);
    glShadeModel(GL_SMOOTH);
    glLightModelfv(GL_LIGHT_MODEL_AMBIENT, amb);
    glLightModeli(GL_LIGHT_MODEL_LOCAL_VIEWER, local);
    glLightModeli(GL_LIGHT_MODEL_TWO_SIDE, two);
    glMaterialfv(GL_FRONT_AND_BACK, GL_AMBIENT, ma);
    glMaterialfv(GL_FRONT_AND_BACK, GL_DIFFUSE, md);
    glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, ms);
    glMaterialfv(GL_FRONT_AND_BACK, GL_EMISSION, me);
    glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, shin);
    int nl = (int)rd();
    for (int i = 0; i < nl && i < 8; i++) {
        float pos[4], a[4] = {0, 0, 0, 1}, d[4] = {0, 0, 0, 1}, s[4] = {0, 0, 0, 1}, sd[3];
        rdv(pos, 4); rdv(a, 3); rdv(d, 3); rdv(s, 3);
        float k0 = rd(), k1 = rd(), k2 = rd();
        rdv(sd, 3);
        float cutoff = rd(), expo = rd();
        GLenum L = GL_LIGHT0 + i;
        glEnable(L);
        glLightfv(L, GL_POSITION, pos);
        glLightfv(L, GL_AMBIENT, a);
        glLightfv(L, GL_DIFFUSE, d);
        glLightfv(L, GL_SPECULAR, s);
        glLightf(L, GL_CONSTANT_ATTENUATION, k0);
        glLightf(L, GL_LINEAR_ATTENUATION, k1);
        glLightf(L, GL_QUADRATIC_ATTENUATION, k2);
        glLightfv(L, GL_SPOT_DIRECTION, sd);
        glLightf(L, GL_SPOT_CUTOFF, cutoff);
        glLightf(L, GL_SPOT_EXPONENT, expo);
    }
    int nv = (int)rd();
    float *v = malloc(sizeof(float) * 8 * (nv > 0 ? nv : 1));
    rdv(v, 8 * nv);
    int nt = (int)rd();
    int *tri = malloc(sizeof(int) * 3 * (nt > 0 ? nt : 1));
    for (int i = 0; i < 3 * nt; i++) tri[i] = (int)rd();
    int tw = (int)rd(), th = (int)rd();
    if (per_fragment) {
        GLuint prog = glCreateProgram();
        glAttachShader(prog, compile(GL_VERTEX_SHADER, VS));
        glAttachShader(prog, compile(GL_FRAGMENT_SHADER, FS));
        glLinkProgram(prog);
        GLint ok;
        glGetProgramiv(prog, GL_LINK_STATUS, &ok);
        if (!ok) { fprintf(stderr, "ffp: the program does not link\n"); return 1; }
        glUseProgram(prog);
        glUniform1i(glGetUniformLocation(prog, "nlights"), nl < 8 ? nl : 8);
        glUniform1i(glGetUniformLocation(prog, "textured"), tw > 0 && th > 0);
        glUniform1i(glGetUniformLocation(prog, "local"), local);
        glUniform1i(glGetUniformLocation(prog, "map"), 0);
    }
    if (tw > 0 && th > 0) {
        unsigned char *tex = malloc((size_t)tw * th * 4);
        for (size_t i = 0; i < (size_t)tw * th * 4; i++) tex[i] = (unsigned char)rd();
        int wrap = (int)rd(), filter = (int)rd();
        GLenum wraps[3] = {GL_REPEAT, GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT};
        GLenum mins[3] = {GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR, GL_NEAREST};
        GLuint id;
        glGenTextures(1, &id);
        glBindTexture(GL_TEXTURE_2D, id);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, tw, th, 0, GL_RGBA, GL_UNSIGNED_BYTE, tex);
        glGenerateMipmap(GL_TEXTURE_2D);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wraps[wrap]);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wraps[wrap]);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, mins[filter]);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter == 2 ? GL_NEAREST : GL_LINEAR);
        glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
        glLightModeli(GL_LIGHT_MODEL_COLOR_CONTROL, GL_SEPARATE_SPECULAR_COLOR);
        glEnable(GL_TEXTURE_2D);
    }
    glBegin(GL_TRIANGLES);
    for (int t = 0; t < 3 * nt; t++) {
        int i = tri[t];
        glTexCoord2fv(v + 8 * i + 6);
        glNormal3fv(v + 8 * i + 3);
        glVertex3fv(v + 8 * i);
    }
    glEnd();
    glFinish();
    for (int y = h - 1; y >= 0; y--)
        for (int x = 0; x < w; x++) fwrite(buf + 4 * ((size_t)y * w + x), 1, 3, stdout);
    OSMesaDestroyContext(ctx);
    return 0;
}
