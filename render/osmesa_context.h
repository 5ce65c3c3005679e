#pragma once
/// OsMesaContext: the OSMesa (software, Mesa < 25.1) backend of GlContext.

#include <memory>
#include <vector>

#include "render/gl_context.h"

namespace palpate {

/// GlContext rendering into a client-memory buffer through OSMesa; not copyable.
/// Thread: create, use and destroy on one thread.
class OsMesaContext final : public GlContext {
 public:
  /// Creates the context and makes it current; errors name the OSMesa call that failed.
  static Result<std::unique_ptr<GlContext>> create(int width, int height);
  ~OsMesaContext() override;

  int width() const override { return width_; }
  int height() const override { return height_; }
  const char* backend_name() const override { return "osmesa"; }
  const GlApi& gl() const override { return gl_; }
  void read_rgba(uint8_t* rgba) override;

 protected:
  bool bind() override;

 private:
  OsMesaContext(int width, int height) : width_(width), height_(height) {}

  int width_ = 0;
  int height_ = 0;
  void* context_ = nullptr;      // OSMesaContext handle
  std::vector<uint8_t> buffer_;  // colour buffer OSMesa renders into (w*h*4, bottom-up)
  GlApi gl_;
};

}  // namespace palpate
