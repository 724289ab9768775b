// The codecs module (crowdrecon_media_codecs): the OpenCV calls behind
// media.hpp. Loaded by media.cpp with dlopen; only its entry point is looked up.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "crowdrecon/media/media.hpp"

namespace crowdrecon::media {
namespace {

class CvVideoReader final : public VideoReader {
 public:
  bool Open(const std::string& path, int api) override { return capture_.open(path, api); }
  bool IsOpened() const override { return capture_.isOpened(); }
  double Get(int property) const override { return capture_.get(property); }
  bool Read(cv::Mat& frame) override { return capture_.read(frame); }

 private:
  cv::VideoCapture capture_;
};

class CvVideoWriter final : public VideoWriter {
 public:
  bool Open(const std::string& path, int api, int fourcc, double fps, cv::Size size, bool color) override {
    return api < 0 ? writer_.open(path, fourcc, fps, size, color) : writer_.open(path, api, fourcc, fps, size, color);
  }
  bool IsOpened() const override { return writer_.isOpened(); }
  bool Set(int property, double value) override { return writer_.set(property, value); }
  void Write(const cv::Mat& frame) override { writer_.write(frame); }
  void Release() override { writer_.release(); }

 private:
  cv::VideoWriter writer_;
};

cv::Mat ReadImageWithOpenCv(const std::string& path, int flags) { return cv::imread(path, flags); }
bool WriteImageWithOpenCv(const std::string& path, const cv::Mat& image) { return cv::imwrite(path, image); }
VideoReader* NewReader() { return new CvVideoReader; }
VideoWriter* NewWriter() { return new CvVideoWriter; }

}  // namespace
}  // namespace crowdrecon::media

extern "C" __attribute__((visibility("default"))) const crowdrecon::media::detail::Codecs* crowdrecon_media_codecs_v1() {
  using namespace crowdrecon::media;
  static const detail::Codecs codecs{detail::kCodecsVersion, ReadImageWithOpenCv, WriteImageWithOpenCv, NewReader,
                                     NewWriter};
  return &codecs;
}
