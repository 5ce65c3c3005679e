#include "render/video_encoder.h"

#include "core/rates.h"

#include <cstdarg>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include "core/atomic_file.h"

namespace palpate {
namespace {

std::string av_error_text(int code) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, buf, sizeof buf);
  return buf;
}

bool supports_yuv420p(const AVCodec* codec) {
  if (codec->pix_fmts == nullptr) return true;  // the encoder does not say: avcodec_open2 decides
  for (const AVPixelFormat* p = codec->pix_fmts; *p != AV_PIX_FMT_NONE; ++p)
    if (*p == AV_PIX_FMT_YUV420P) return true;
  return false;
}

}  // namespace

namespace {

// the last error line libav logged on this thread (its muxer and encoder log through av_log)
thread_local std::string t_libav_said;

void keep_libav_line(void* avcl, int level, const char* fmt, va_list args) {
  if (level > AV_LOG_ERROR) return;
  char line[512];
  int prefix = 0;  // no "[mp4 @ 0x...]"
  av_log_format_line2(avcl, level, fmt, args, line, sizeof line, &prefix);
  std::string text(line);
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  if (!text.empty()) t_libav_said = text;
}

}  // namespace

struct VideoEncoder::Impl {
  std::string path;
  std::optional<AtomicFile> file;  // owns the temporary until renamed
  int width = 0, height = 0;       // encoded size (even)
  int src_stride = 0;              // bytes per RGBA input row
  int fps = static_cast<int>(kDefaultFrameRate_hz);  // open() sets the run's
  std::string encoder;
  AVFormatContext* fmt = nullptr;
  AVCodecContext* ctx = nullptr;
  AVStream* stream = nullptr;
  SwsContext* sws = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* pkt = nullptr;
  int64_t frames = 0;
  int64_t last_index = -1;
  int64_t bytes = 0;
  bool header_written = false;
  bool finished = false;

  ~Impl() {
    sws_freeContext(sws);
    av_frame_free(&frame);
    av_packet_free(&pkt);
    avcodec_free_context(&ctx);
    if (fmt) {
      if (fmt->pb) avio_closep(&fmt->pb);
      avformat_free_context(fmt);
    }
    if (file) file->discard();
  }

  Error fail(const std::string& what, int code) const {
    std::string said;
    said.swap(t_libav_said);
    return make_error("video '", path, "': ", what, ": ", av_error_text(code), said.empty() ? "" : " (libav: ", said,
                      said.empty() ? "" : ")");
  }

  // sends a frame (null: flush) and writes every packet the encoder returns
  Status send(const AVFrame* f) {
    int rc = avcodec_send_frame(ctx, f);
    if (rc < 0) return fail("encoder " + encoder + " refused a frame", rc);
    for (;;) {
      rc = avcodec_receive_packet(ctx, pkt);
      if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return Ok{};
      if (rc < 0) return fail("encoder " + encoder + " failed", rc);
      if (pkt->duration == 0) pkt->duration = 1;  // the last frame lasts one period
      av_packet_rescale_ts(pkt, ctx->time_base, stream->time_base);
      pkt->stream_index = stream->index;
      rc = av_interleaved_write_frame(fmt, pkt);
      if (rc < 0) return fail("cannot write", rc);
    }
  }
};

VideoEncoder::VideoEncoder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
VideoEncoder::~VideoEncoder() = default;

Result<std::unique_ptr<VideoEncoder>> VideoEncoder::open(const std::string& path, int width, int height,
                                                         int frame_rate_hz) {
  auto im = std::make_unique<Impl>();
  im->path = path;
  if (width < 2 || height < 2) return make_error("video '", path, "': frame ", std::to_string(width), "x", std::to_string(height),
                                       " is below 2x2");
  if (frame_rate_hz < 1 || frame_rate_hz > 1000)
    return make_error("video '", path, "': frame rate ", std::to_string(frame_rate_hz), " Hz is outside 1..1000");
  im->width = width & ~1;
  im->height = height & ~1;
  im->src_stride = width * 4;
  im->fps = frame_rate_hz;
  // libav's own lines are kept for the error that follows them, never printed raw beside palpate's
  av_log_set_callback(keep_libav_line);
  t_libav_said.clear();

  auto file = AtomicFile::open(path, "video");
  if (!file) return file.error();
  im->file.emplace(std::move(file).value());
  const std::string tmp = im->file->temp_path();

  int rc = avformat_alloc_output_context2(&im->fmt, nullptr, "mp4", tmp.c_str());
  if (rc < 0 || im->fmt == nullptr) return im->fail("no MP4 muxer in this libavformat", rc);

  // the first H.264 encoder that opens with yuv420p at this size
  std::string tried;
  std::vector<const AVCodec*> candidates;
  for (const char* name : {"libx264", "libopenh264"})
    if (const AVCodec* c = avcodec_find_encoder_by_name(name)) candidates.push_back(c);
  if (const AVCodec* c = avcodec_find_encoder(AV_CODEC_ID_H264)) candidates.push_back(c);
  for (const AVCodec* codec : candidates) {
    if (!tried.empty()) tried += "; ";
    tried += codec->name;
    if (!supports_yuv420p(codec)) {
      tried += ": no yuv420p";
      continue;
    }
    AVCodecContext* ctx = avcodec_alloc_context3(codec);
    ctx->width = im->width;
    ctx->height = im->height;
    ctx->pix_fmt = AV_PIX_FMT_YUV420P;
    ctx->time_base = AVRational{1, frame_rate_hz};
    ctx->framerate = AVRational{frame_rate_hz, 1};
    ctx->gop_size = frame_rate_hz;  // a key frame a second, for seeking in a browser
    ctx->color_range = AVCOL_RANGE_MPEG;
    ctx->colorspace = AVCOL_SPC_BT709;
    ctx->color_primaries = AVCOL_PRI_BT709;
    ctx->color_trc = AVCOL_TRC_BT709;
    // one thread: the encoder shares the machine with the sim, the servo and the PNG writer
    ctx->thread_count = 1;
    if (im->fmt->oformat->flags & AVFMT_GLOBALHEADER) ctx->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    AVDictionary* opts = nullptr;
    // ultrafast at CRF 26 against veryfast at CRF 20 on bunny_pull (six alternating recordings on a quiet machine):
    // encode p50 2.5 vs 3.3 ms a frame, 11 % less CPU per run, PSNR against the PNG frames 50.1 vs 44.0 dB, files
    // 1.8x larger (509 vs 285 kB for 4 s); the recording is then 4.1x faster than real time instead of 3.6x
    av_dict_set(&opts, "preset", "ultrafast", 0);
    av_dict_set(&opts, "crf", "26", 0);
    rc = avcodec_open2(ctx, codec, &opts);
    av_dict_free(&opts);
    if (rc < 0) {
      tried += ": " + av_error_text(rc);
      avcodec_free_context(&ctx);
      continue;
    }
    im->ctx = ctx;
    im->encoder = codec->name;
    break;
  }
  if (im->ctx == nullptr)
    return make_error("video '", path, "': no H.264 encoder in this libavcodec opens (tried: ",
                      tried.empty() ? "none found" : tried, "); install one (Debian libavcodec59 with libx264) or use --no-video");

  im->stream = avformat_new_stream(im->fmt, nullptr);
  if (im->stream == nullptr) return im->fail("cannot add a stream", AVERROR(ENOMEM));
  rc = avcodec_parameters_from_context(im->stream->codecpar, im->ctx);
  if (rc < 0) return im->fail("cannot copy the encoder parameters", rc);
  im->stream->time_base = im->ctx->time_base;
  im->stream->avg_frame_rate = im->ctx->framerate;
  rc = avio_open(&im->fmt->pb, tmp.c_str(), AVIO_FLAG_WRITE);
  if (rc < 0) return make_error("video '", path, "': cannot open '", tmp, "': ", av_error_text(rc));
  AVDictionary* mux = nullptr;
  av_dict_set(&mux, "movflags", "+faststart", 0);  // moov before mdat: plays while it downloads
  rc = avformat_write_header(im->fmt, &mux);
  av_dict_free(&mux);
  if (rc < 0) return im->fail("cannot write the MP4 header", rc);
  im->header_written = true;

  // RGBA -> BT.709 limited-range yuv420p, as the stream is tagged
  im->sws = sws_getContext(im->width, im->height, AV_PIX_FMT_RGBA, im->width, im->height, AV_PIX_FMT_YUV420P,
                           SWS_BILINEAR | SWS_ACCURATE_RND, nullptr, nullptr, nullptr);
  if (im->sws == nullptr) return make_error("video '", path, "': no RGBA to yuv420p conversion in this libswscale");
  const int* bt709 = sws_getCoefficients(SWS_CS_ITU709);
  sws_setColorspaceDetails(im->sws, bt709, 1, bt709, 0, 0, 1 << 16, 1 << 16);
  im->frame = av_frame_alloc();
  im->pkt = av_packet_alloc();
  if (im->frame == nullptr || im->pkt == nullptr) return im->fail("cannot allocate a frame", AVERROR(ENOMEM));
  im->frame->format = AV_PIX_FMT_YUV420P;
  im->frame->width = im->width;
  im->frame->height = im->height;
  rc = av_frame_get_buffer(im->frame, 0);
  if (rc < 0) return im->fail("cannot allocate a frame", rc);
  return std::unique_ptr<VideoEncoder>(new VideoEncoder(std::move(im)));
}

Status VideoEncoder::encode(const uint8_t* rgba, int64_t index) {
  Impl& im = *impl_;
  if (im.finished) return make_error("video '", im.path, "': frame ", std::to_string(index), " after finish()");
  if (index <= im.last_index)
    return make_error("video '", im.path, "': frame index ", std::to_string(index), " does not follow ",
                      std::to_string(im.last_index));
  const int rc = av_frame_make_writable(im.frame);
  if (rc < 0) return im.fail("cannot reuse the frame", rc);
  const uint8_t* src[4] = {rgba, nullptr, nullptr, nullptr};
  const int stride[4] = {im.src_stride, 0, 0, 0};
  sws_scale(im.sws, src, stride, 0, im.height, im.frame->data, im.frame->linesize);
  im.frame->pts = index;
  if (auto st = im.send(im.frame); !st) return st;
  im.last_index = index;
  ++im.frames;
  return Ok{};
}

Status VideoEncoder::finish() {
  Impl& im = *impl_;
  if (im.finished) return Ok{};
  im.finished = true;
  if (auto st = im.send(nullptr); !st) return st;
  // faststart: the muxer reopens the temporary and moves the index in front of the data
  int rc = av_write_trailer(im.fmt);
  if (rc < 0) return im.fail("cannot finish the MP4", rc);
  rc = avio_closep(&im.fmt->pb);
  if (rc < 0) return im.fail("cannot close", rc);
  std::error_code ec;
  const auto size = std::filesystem::file_size(im.file->temp_path(), ec);
  if (auto st = im.file->commit(); !st) return st;
  im.file.reset();
  im.bytes = ec ? 0 : static_cast<int64_t>(size);
  return Ok{};
}

const std::string& VideoEncoder::encoder_name() const { return impl_->encoder; }
const std::string& VideoEncoder::path() const { return impl_->path; }
int64_t VideoEncoder::frames() const { return impl_->frames; }
int64_t VideoEncoder::bytes() const { return impl_->bytes; }
int VideoEncoder::frame_rate_hz() const { return impl_->fps; }

}  // namespace palpate
