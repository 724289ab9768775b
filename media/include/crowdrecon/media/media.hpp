// Pictures and videos through OpenCV's imgcodecs and videoio, loaded on first
// use (media/CMakeLists.txt says why). Each function is the OpenCV call of the
// same name, with the same arguments, results and exceptions (cv::Exception);
// the constants (cv::IMREAD_*, cv::CAP_*, cv::VIDEOWRITER_PROP_*) are OpenCV's.
// If the codecs module cannot be loaded, the first call throws SetupError
// (common/error.hpp) naming the module's path and the loader's reason.
//
// For the .cpp files of modules that already use OpenCV (geometry, observe,
// viz); no header of theirs includes this one.
#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <string>

namespace crowdrecon::media {

// cv::imread and cv::imwrite.
cv::Mat ReadImage(const std::string& path, int flags);
bool WriteImage(const std::string& path, const cv::Mat& image);

// cv::VideoCapture.
class VideoReader {
 public:
  virtual ~VideoReader() = default;
  virtual bool Open(const std::string& path, int api) = 0;
  virtual bool IsOpened() const = 0;
  virtual double Get(int property) const = 0;
  virtual bool Read(cv::Mat& frame) = 0;
};

// cv::VideoWriter.
class VideoWriter {
 public:
  virtual ~VideoWriter() = default;
  // api < 0: any backend (cv::VideoWriter::open without an api).
  virtual bool Open(const std::string& path, int api, int fourcc, double fps, cv::Size size, bool color) = 0;
  virtual bool IsOpened() const = 0;
  virtual bool Set(int property, double value) = 0;
  virtual void Write(const cv::Mat& frame) = 0;
  virtual void Release() = 0;
};

std::unique_ptr<VideoReader> MakeVideoReader();
std::unique_ptr<VideoWriter> MakeVideoWriter();

// A video file as VideoWriter::Release left it, checked for completeness:
// "" if its container's structure (AVI: RIFF chunks; MP4: ISO boxes) ends
// exactly at the end of the file, else what is wrong ("ends at 8192 bytes
// where its RIFF chunk says 412356"). OpenCV's writers report no write
// error: a full disk gave a truncated video and "31 frames written".
std::string IncompleteVideo(const std::string& path);
// Throws InputError naming `video` (the output the partial file `path` will
// become) if IncompleteVideo finds something wrong.
void RequireCompleteVideo(const std::string& path, const std::string& video);

// cv::VideoWriter::fourcc: the four characters of a codec as one int.
constexpr int FourCc(char a, char b, char c, char d) {
  return (a & 255) + ((b & 255) << 8) + ((c & 255) << 16) + ((d & 255) << 24);
}

namespace detail {
// What the codecs module gives (crowdrecon_media_codecs_v1 returns it).
struct Codecs {
  int version;  // kCodecsVersion
  cv::Mat (*read_image)(const std::string& path, int flags);
  bool (*write_image)(const std::string& path, const cv::Mat& image);
  VideoReader* (*new_reader)();
  VideoWriter* (*new_writer)();
};
constexpr int kCodecsVersion = 1;
}  // namespace detail

}  // namespace crowdrecon::media
