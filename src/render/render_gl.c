// SPDX-License-Identifier: MIT
// Offscreen OpenGL context through EGL, loaded at run time so that a machine without EGL still
// runs everything else and gets a clear error here. Displays are tried in order: Mesa's
// surfaceless platform (no display server, software llvmpipe or a DRI GPU), the first EGL device
// (a GPU driver's EGL, e.g. NVIDIA), then the default display.
#define _POSIX_C_SOURCE 200809L
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <dlfcn.h>
#include <stdio.h>
#include <string.h>

#include "render_internal.h"

struct gl_api {
  // EGL
  PFNEGLGETPROCADDRESSPROC GetProcAddress;
  PFNEGLGETDISPLAYPROC GetDisplay;
  PFNEGLINITIALIZEPROC Initialize;
  PFNEGLTERMINATEPROC Terminate;
  PFNEGLCHOOSECONFIGPROC ChooseConfig;
  PFNEGLBINDAPIPROC BindAPI;
  PFNEGLCREATECONTEXTPROC CreateContext;
  PFNEGLDESTROYCONTEXTPROC DestroyContext;
  PFNEGLCREATEPBUFFERSURFACEPROC CreatePbufferSurface;
  PFNEGLDESTROYSURFACEPROC DestroySurface;
  PFNEGLMAKECURRENTPROC MakeCurrent;
  PFNEGLGETERRORPROC GetError;
  PFNEGLQUERYSTRINGPROC QueryString;
  PFNEGLRELEASETHREADPROC ReleaseThread;
  PFNEGLGETPLATFORMDISPLAYEXTPROC GetPlatformDisplayEXT;
  PFNEGLQUERYDEVICESEXTPROC QueryDevicesEXT;
  // GL 1.x, fetched through eglGetProcAddress
  GLuint (*GenLists)(GLsizei);
  void (*NewList)(GLuint, GLenum);
  void (*EndList)(void);
  void (*DeleteLists)(GLuint, GLsizei);
  void (*Begin)(GLenum);
  void (*End)(void);
  void (*Normal3fv)(const GLfloat*);
  void (*Vertex3fv)(const GLfloat*);
  void (*Color3fv)(const GLfloat*);
  const GLubyte* (*GetString)(GLenum);
  GLenum (*GetErrorGL)(void);
  // the shadow map's depth bias
  void (*Enable)(GLenum);
  void (*Disable)(GLenum);
  void (*PolygonOffset)(GLfloat, GLfloat);
};

// a symbol of libEGL
static void* sym(gl_ctx* g, const char* name) {
  return dlsym(g->lib, name);
}

// load libEGL and its entry points
static vd_status load_egl(gl_ctx* g, vd_error* err) {
  g->lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_LOCAL);
  if (!g->lib)
    return vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0,
                        "no OpenGL context: libEGL.so.1 cannot be loaded (install libegl1 and "
                        "libegl-mesa0, see scripts/deps.sh)");
  gl_api* a = vd_calloc(1, sizeof *a);
  if (!a) return vd_error_set(err, VD_ERR_NOMEM, "", 0, 0, "out of memory");
  g->api = a;
#define LOAD(field, name)                                                                          \
  do {                                                                                             \
    *(void**)&a->field = sym(g, name);                                                             \
    if (!a->field)                                                                                 \
      return vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0, "no OpenGL context: libEGL lacks %s", \
                          name);                                                                   \
  } while (0)
  LOAD(GetProcAddress, "eglGetProcAddress");
  LOAD(GetDisplay, "eglGetDisplay");
  LOAD(Initialize, "eglInitialize");
  LOAD(Terminate, "eglTerminate");
  LOAD(ChooseConfig, "eglChooseConfig");
  LOAD(BindAPI, "eglBindAPI");
  LOAD(CreateContext, "eglCreateContext");
  LOAD(DestroyContext, "eglDestroyContext");
  LOAD(CreatePbufferSurface, "eglCreatePbufferSurface");
  LOAD(DestroySurface, "eglDestroySurface");
  LOAD(MakeCurrent, "eglMakeCurrent");
  LOAD(GetError, "eglGetError");
  LOAD(QueryString, "eglQueryString");
  LOAD(ReleaseThread, "eglReleaseThread");
#undef LOAD
  a->GetPlatformDisplayEXT =
      (PFNEGLGETPLATFORMDISPLAYEXTPROC)a->GetProcAddress("eglGetPlatformDisplayEXT");
  a->QueryDevicesEXT = (PFNEGLQUERYDEVICESEXTPROC)a->GetProcAddress("eglQueryDevicesEXT");
  return VD_OK;
}

// does the space-separated extension list have ext?
static int has_ext(const char* list, const char* ext) {
  size_t n = strlen(ext);
  for (const char* p = list; p && (p = strstr(p, ext)); p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == 0)) return 1;
  return 0;
}

// initialise a display; returns 1 and fills the platform name on success
static int try_display(gl_ctx* g, EGLDisplay dpy, const char* platform, char* tried, size_t cap) {
  gl_api* a = g->api;
  EGLint maj = 0, min = 0;
  size_t len = strlen(tried);
  if (dpy == EGL_NO_DISPLAY) {
    snprintf(tried + len, cap - len, "%s%s: no display", len ? "; " : "", platform);
    return 0;
  }
  if (!a->Initialize(dpy, &maj, &min)) {
    snprintf(tried + len, cap - len, "%s%s: eglInitialize error 0x%x", len ? "; " : "", platform,
             (unsigned)a->GetError());
    return 0;
  }
  g->dpy = dpy;
  snprintf(g->info, sizeof g->info, "EGL %d.%d (%s)", maj, min, platform);
  snprintf(g->id.platform, sizeof g->id.platform, "%s", platform);
  return 1;
}

vd_status gl_create(gl_ctx* g, vd_error* err) {
  memset(g, 0, sizeof *g);
  vd_status st = load_egl(g, err);
  if (st) return st;
  gl_api* a = g->api;
  // displays: surfaceless Mesa, then the first EGL device, then the default display
  char tried[512] = "";
  const char* client = a->QueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  int ok = 0;
  if (a->GetPlatformDisplayEXT && has_ext(client, "EGL_MESA_platform_surfaceless"))
    ok = try_display(
        g, a->GetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL),
        "surfaceless", tried, sizeof tried);
  if (!ok && a->GetPlatformDisplayEXT && a->QueryDevicesEXT &&
      has_ext(client, "EGL_EXT_platform_device")) {
    EGLDeviceEXT dev[4];
    EGLint ndev = 0;
    if (a->QueryDevicesEXT(4, dev, &ndev) && ndev > 0)
      ok = try_display(g, a->GetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, dev[0], NULL), "device",
                       tried, sizeof tried);
  }
  if (!ok)
    ok = try_display(g, a->GetDisplay(EGL_DEFAULT_DISPLAY), "default display", tried, sizeof tried);
  if (!ok)
    return vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0,
                        "no OpenGL context: no EGL display could be initialised (%s); install "
                        "libegl-mesa0 and libgl1-mesa-dri for software rendering",
                        tried);
  // a desktop OpenGL config with depth and stencil (MuJoCo's needs), then the context
  const EGLint cfg_attr[] = {EGL_SURFACE_TYPE,
                             EGL_PBUFFER_BIT,
                             EGL_RED_SIZE,
                             8,
                             EGL_GREEN_SIZE,
                             8,
                             EGL_BLUE_SIZE,
                             8,
                             EGL_ALPHA_SIZE,
                             8,
                             EGL_DEPTH_SIZE,
                             24,
                             EGL_STENCIL_SIZE,
                             8,
                             EGL_RENDERABLE_TYPE,
                             EGL_OPENGL_BIT,
                             EGL_NONE};
  EGLConfig cfg;
  EGLint ncfg = 0;
  if (!a->ChooseConfig(g->dpy, cfg_attr, &cfg, 1, &ncfg) || ncfg < 1)
    return vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0,
                        "no OpenGL context: %s has no RGBA8 + depth 24 + stencil 8 OpenGL config "
                        "(EGL error 0x%x)",
                        g->info, (unsigned)a->GetError());
  if (!a->BindAPI(EGL_OPENGL_API))
    return vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0,
                        "no OpenGL context: %s cannot bind desktop OpenGL", g->info);
  g->ctx = a->CreateContext(g->dpy, cfg, EGL_NO_CONTEXT, NULL);
  if (g->ctx == EGL_NO_CONTEXT)
    return vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0,
                        "no OpenGL context: eglCreateContext failed (0x%x)",
                        (unsigned)a->GetError());
  // current without a surface when the display allows it, else on a 1x1 pbuffer
  const char* dext = a->QueryString(g->dpy, EGL_EXTENSIONS);
  if (!has_ext(dext, "EGL_KHR_surfaceless_context")) {
    const EGLint pb[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
    g->surf = a->CreatePbufferSurface(g->dpy, cfg, pb);
    if (g->surf == EGL_NO_SURFACE)
      return vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0,
                          "no OpenGL context: no pbuffer surface (0x%x)", (unsigned)a->GetError());
  }
  st = gl_current(g, err);
  if (st) return st;
    // GL 1.x entry points (display lists, immediate mode) for the plant and cloud geometry
#define GLFN(field, name)                                                                          \
  do {                                                                                             \
    a->field = (__typeof__(a->field))a->GetProcAddress(name);                                      \
    if (!a->field)                                                                                 \
      return vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0, "no OpenGL context: %s not found",    \
                          name);                                                                   \
  } while (0)
  GLFN(GenLists, "glGenLists");
  GLFN(NewList, "glNewList");
  GLFN(EndList, "glEndList");
  GLFN(DeleteLists, "glDeleteLists");
  GLFN(Begin, "glBegin");
  GLFN(End, "glEnd");
  GLFN(Normal3fv, "glNormal3fv");
  GLFN(Vertex3fv, "glVertex3fv");
  GLFN(Color3fv, "glColor3fv");
  GLFN(GetString, "glGetString");
  GLFN(GetErrorGL, "glGetError");
  GLFN(Enable, "glEnable");
  GLFN(Disable, "glDisable");
  GLFN(PolygonOffset, "glPolygonOffset");
#undef GLFN
  const char* ver = (const char*)a->GetString(GL_VERSION);
  const char* ren = (const char*)a->GetString(GL_RENDERER);
  const char* ven = (const char*)a->GetString(GL_VENDOR);
  snprintf(g->id.version, sizeof g->id.version, "%s", ver ? ver : "?");
  snprintf(g->id.renderer, sizeof g->id.renderer, "%s", ren ? ren : "?");
  snprintf(g->id.vendor, sizeof g->id.vendor, "%s", ven ? ven : "?");
  // Mesa's software rasterisers name themselves in GL_RENDERER
  g->id.software = strstr(g->id.renderer, "llvmpipe") || strstr(g->id.renderer, "softpipe") ||
                   strstr(g->id.renderer, "swrast") || strstr(g->id.renderer, "Software");
  size_t len = strlen(g->info);
  snprintf(g->info + len, sizeof g->info - len, ", OpenGL %s, %s", g->id.version, g->id.renderer);
  return VD_OK;
}

vd_status gl_current(gl_ctx* g, vd_error* err) {
  gl_api* a = g->api;
  EGLSurface s = g->surf ? g->surf : EGL_NO_SURFACE;
  if (!a->MakeCurrent(g->dpy, s, s, g->ctx))
    return vd_error_set(err, VD_ERR_UNSUPPORTED, "", 0, 0,
                        "no OpenGL context: eglMakeCurrent failed (0x%x)", (unsigned)a->GetError());
  return VD_OK;
}

void gl_release(gl_ctx* g) {
  if (g->api && g->dpy) g->api->MakeCurrent(g->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
}

void gl_destroy(gl_ctx* g) {
  gl_api* a = g->api;
  if (a && g->dpy) {
    a->MakeCurrent(g->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (g->ctx) a->DestroyContext(g->dpy, g->ctx);
    if (g->surf) a->DestroySurface(g->dpy, g->surf);
    // the display stays initialised: EGL displays are shared per process and other renderers
    // may still use it (eglTerminate would pull their contexts away)
    a->ReleaseThread();
  }
  vd_free(a, sizeof *a);
  // libEGL stays loaded: drivers register exit handlers that must outlive the context
  memset(g, 0, sizeof *g);
}

unsigned gl_list(gl_ctx* g, const gl_tris* t) {
  gl_api* a = g->api;
  GLuint list = a->GenLists(1);
  if (!list) return 0;
  a->NewList(list, GL_COMPILE);
  a->Begin(GL_TRIANGLES);
  for (int k = 0; k < 3 * t->ntri; k++) {
    if (t->rgb) a->Color3fv(t->rgb + 3 * k);
    a->Normal3fv(t->normal + 3 * k);
    a->Vertex3fv(t->pos + 3 * k);
  }
  a->End();
  a->EndList();
  if (a->GetErrorGL() != GL_NO_ERROR) {
    a->DeleteLists(list, 1);
    return 0;
  }
  return list;
}

void gl_list_free(gl_ctx* g, unsigned list) {
  if (list && g->api) g->api->DeleteLists(list, 1);
}

void gl_polygon_offset(gl_ctx* g, float factor, float units) {
  gl_api* a = g->api;
  if (factor == 0 && units == 0) {
    a->Disable(GL_POLYGON_OFFSET_FILL);
    return;
  }
  a->PolygonOffset(factor, units);
  a->Enable(GL_POLYGON_OFFSET_FILL);
}
