#include <fstream>
#include <iostream>

#include "api/Sha256.h"
#include "client/Commands.h"
#include "renderer/scene/GltfPackage.h"

namespace radiant::client {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UsageError("cannot read " + path);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

void writeFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw UsageError("cannot write " + path);
}

std::string sceneFileBytes(const std::string& path, std::string* note) {
  try {
    PackResult r = packGltfFile(path);
    if (note && r.packed)
      *note = "packed " + path + " and " + std::to_string(r.externalFiles) + " referenced file" +
              (r.externalFiles == 1 ? "" : "s") + " into one GLB (" + std::to_string(r.bytes.size()) + " bytes)";
    return std::move(r.bytes);
  } catch (const PackError& e) {
    throw UsageError(path + (e.pointer.empty() ? "" : ": " + e.pointer) + ": " + e.what());
  }
}

std::string ensureSceneUploaded(const HttpClient& http, const std::string& bytes, const std::string& fileName,
                                bool verbose) {
  const std::string digest = api::sceneDigest(bytes);
  const HttpResponse head = http.head("/v1/scenes/" + digest, sceneHeader(digest));
  if (head.status == 200) {
    if (verbose) std::cerr << "scene " << digest << " already on the server\n";
    return digest;
  }
  if (head.status != 404) HttpClient::expectOk(head);
  const bool glb = bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0;
  const HttpResponse r = http.put("/v1/scenes", bytes, glb ? "model/gltf-binary" : "model/gltf+json", sceneHeader(digest));
  HttpClient::expectOk(r);
  const std::string stored = r.json().value("digest", "");
  if (stored != digest)
    throw ServerError(r.status, {{"title", "Digest mismatch"}, {"status", r.status},
                                 {"detail", "uploaded " + fileName + " as " + digest + " but the server stored " + stored}});
  if (verbose) std::cerr << "uploaded " << fileName << " as " << digest << " (" << bytes.size() << " bytes)\n";
  return digest;
}

std::string ensureImageUploaded(const HttpClient& http, const std::string& path, bool verbose) {
  const std::string bytes = readFile(path);
  const std::string digest = api::sceneDigest(bytes);
  const HttpResponse head = http.head("/v1/images/" + digest);
  if (head.status == 200) return digest;
  if (head.status != 404) HttpClient::expectOk(head);
  const bool exr = bytes.size() >= 4 && bytes.compare(0, 4, "\x76\x2f\x31\x01") == 0;
  const HttpResponse r = http.put("/v1/images", bytes, exr ? "image/x-exr" : "image/vnd.radiance");
  HttpClient::expectOk(r);
  if (verbose) std::cerr << "uploaded " << path << " as " << digest << " (" << bytes.size() << " bytes)\n";
  return digest;
}

}  // namespace radiant::client
