#include "cranioplan/algorithms/io/write_3mf.h"

#include <Model/COM/NMR_DLLInterfaces.h>

#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>

#include "cranioplan/model/error.h"

namespace cranioplan {
namespace {

// lib3mf's objects are released through one function; a unique_ptr with it as deleter.
struct Release {
  void operator()(NMR::PLib3MFBase* p) const {
    if (p) NMR::lib3mf_release(p);
  }
};
template <class T>
using Owned = std::unique_ptr<T, Release>;

[[noreturn]] void fail(const std::string& path, NMR::PLib3MFBase* from, const std::string& what) {
  DWORD code = 0;
  LPCSTR message = nullptr;
  if (from) NMR::lib3mf_getlasterror(from, &code, &message);
  char buf[64];
  std::snprintf(buf, sizeof(buf), " (lib3mf error 0x%lx)", static_cast<unsigned long>(code));
  throw InputError(path, what + (message && *message ? std::string(": ") + message : "") + buf);
}

void check(LIB3MFRESULT r, const std::string& path, NMR::PLib3MFBase* from,
           const std::string& what) {
  if (r != LIB3MF_OK) fail(path, from, what);
}

// 64-bit FNV-1a of `text` from `seed`.
uint64_t fnv1a(const std::string& text, uint64_t seed) {
  uint64_t h = seed;
  for (const unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  return h;
}

// A UUID (RFC 4122 layout, version 4 bits) taken from a hash of `text`: the same content, the
// same id.
std::string uuid_from(const std::string& text) {
  char h[33];
  std::snprintf(h, sizeof(h), "%016llx%016llx",
                static_cast<unsigned long long>(fnv1a(text, 14695981039346656037ull)),
                static_cast<unsigned long long>(fnv1a(text, 0x9e3779b97f4a7c15ull)));
  std::string s(h, 32);
  s[12] = '4';
  s[16] = "89ab"[std::stoi(s.substr(16, 1), nullptr, 16) & 3];
  return s.substr(0, 8) + "-" + s.substr(8, 4) + "-" + s.substr(12, 4) + "-" + s.substr(16, 4) +
         "-" + s.substr(20, 12);
}

std::string utf8_of(const std::function<LIB3MFRESULT(LPSTR, ULONG, ULONG*)>& get) {
  ULONG needed = 0;
  if (get(nullptr, 0, &needed) != LIB3MF_OK) return {};
  std::string s(needed + 1, '\0');
  if (get(s.data(), static_cast<ULONG>(s.size()), &needed) != LIB3MF_OK) return {};
  s.resize(needed);
  return s;
}

}  // namespace

std::string encode_3mf(const std::vector<Part3mf>& parts,
                       const std::vector<std::pair<std::string, std::string>>& metadata) {
  const std::string where = "3MF";
  NMR::PLib3MFModel* raw = nullptr;
  check(NMR::lib3mf_createmodel(&raw), where, nullptr, "lib3mf could not make a model");
  const Owned<NMR::PLib3MFModel> model(raw);
  check(NMR::lib3mf_model_setunit(model.get(), NMR::MODELUNIT_MILLIMETER), where, model.get(),
        "setting millimetres");
  for (const auto& [key, value] : metadata)
    check(NMR::lib3mf_model_addmetadatautf8(model.get(), key.c_str(), value.c_str()), where,
          model.get(), "metadata " + key);
  std::string all;  // every part's content, for the build's UUID
  for (const Part3mf& part : parts) {
    const SkullMesh& m = *part.mesh;
    std::vector<NMR::MODELMESHVERTEX> vertices(m.n_vertices());
    std::vector<NMR::MODELMESHTRIANGLE> triangles;
    triangles.reserve(m.n_faces());
    for (auto vh : m.vertices())
      for (int k = 0; k < 3; ++k)
        vertices[static_cast<size_t>(vh.idx())].m_fPosition[k] = static_cast<float>(m.point(vh)[k]);
    for (auto fh : m.faces()) {
      NMR::MODELMESHTRIANGLE t;
      int k = 0;
      for (auto vh : m.fv_range(fh)) t.m_nIndices[k++] = static_cast<DWORD>(vh.idx());
      triangles.push_back(t);
    }
    NMR::PLib3MFModelMeshObject* raw_mesh = nullptr;
    check(NMR::lib3mf_model_addmeshobject(model.get(), &raw_mesh), where, model.get(),
          "adding " + part.name);
    const Owned<NMR::PLib3MFModelMeshObject> mesh(raw_mesh);
    check(NMR::lib3mf_object_setnameutf8(mesh.get(), part.name.c_str()), where, mesh.get(),
          "naming " + part.name);
    check(NMR::lib3mf_meshobject_setgeometry(mesh.get(), vertices.data(),
                                             static_cast<DWORD>(vertices.size()), triangles.data(),
                                             static_cast<DWORD>(triangles.size())),
          where, mesh.get(), part.name + "'s triangles");
    const std::string content = part.name +
                                std::string(reinterpret_cast<const char*>(vertices.data()),
                                            vertices.size() * sizeof(NMR::MODELMESHVERTEX)) +
                                std::string(reinterpret_cast<const char*>(triangles.data()),
                                            triangles.size() * sizeof(NMR::MODELMESHTRIANGLE));
    all += uuid_from(content);
    check(NMR::lib3mf_object_setuuidutf8(mesh.get(), uuid_from("object " + content).c_str()), where,
          mesh.get(), part.name + "'s id");
    NMR::PLib3MFModelBuildItem* raw_item = nullptr;
    check(NMR::lib3mf_model_addbuilditem(model.get(), mesh.get(), nullptr, &raw_item), where,
          model.get(), "placing " + part.name);
    const Owned<NMR::PLib3MFModelBuildItem> item(raw_item);
    check(NMR::lib3mf_builditem_setuuidutf8(item.get(), uuid_from("item " + content).c_str()),
          where, item.get(), part.name + "'s build id");
  }
  check(NMR::lib3mf_model_setbuilduuidutf8(model.get(), uuid_from("build " + all).c_str()), where,
        model.get(), "the build's id");
  NMR::PLib3MFModelWriter* raw_writer = nullptr;
  check(NMR::lib3mf_model_querywriter(model.get(), "3mf", &raw_writer), where, model.get(),
        "lib3mf has no 3MF writer");
  const Owned<NMR::PLib3MFModelWriter> writer(raw_writer);
  ULONG64 size = 0;
  check(NMR::lib3mf_writer_getstreamsize(writer.get(), &size), where, writer.get(),
        "sizing the package");
  std::string bytes(static_cast<size_t>(size), '\0');
  check(NMR::lib3mf_writer_writetobuffer(writer.get(), reinterpret_cast<BYTE*>(bytes.data()), size),
        where, writer.get(), "writing the package");
  return bytes;
}

Read3mf read_3mf(const std::string& path) {
  NMR::PLib3MFModel* raw = nullptr;
  check(NMR::lib3mf_createmodel(&raw), path, nullptr, "lib3mf could not make a model");
  const Owned<NMR::PLib3MFModel> model(raw);
  NMR::PLib3MFModelReader* raw_reader = nullptr;
  check(NMR::lib3mf_model_queryreader(model.get(), "3mf", &raw_reader), path, model.get(),
        "lib3mf has no 3MF reader");
  const Owned<NMR::PLib3MFModelReader> reader(raw_reader);
  check(NMR::lib3mf_reader_readfromfileutf8(reader.get(), path.c_str()), path, reader.get(),
        "not a 3MF package lib3mf can read");
  Read3mf out;
  DWORD unit = NMR::MODELUNIT_MILLIMETER;
  check(NMR::lib3mf_model_getunit(model.get(), &unit), path, model.get(), "its unit");
  static const double kUnitMm[] = {1e-3, 1.0, 10.0, 25.4, 304.8, 1000.0};
  if (unit > NMR::MODELUNIT_METER) throw InputError(path, "an unknown length unit");
  out.unit_mm = kUnitMm[unit];
  DWORD count = 0;
  check(NMR::lib3mf_model_getmetadatacount(model.get(), &count), path, model.get(), "metadata");
  for (DWORD k = 0; k < count; ++k) {
    const std::string key = utf8_of([&](LPSTR b, ULONG n, ULONG* need) {
      return NMR::lib3mf_model_getmetadatakeyutf8(model.get(), k, b, n, need);
    });
    out.metadata[key] = utf8_of([&](LPSTR b, ULONG n, ULONG* need) {
      return NMR::lib3mf_model_getmetadatavalueutf8(model.get(), k, b, n, need);
    });
  }
  NMR::PLib3MFModelResourceIterator* raw_it = nullptr;
  check(NMR::lib3mf_model_getmeshobjects(model.get(), &raw_it), path, model.get(), "its objects");
  const Owned<NMR::PLib3MFModelResourceIterator> it(raw_it);
  BOOL more = false;
  while (NMR::lib3mf_resourceiterator_movenext(it.get(), &more) == LIB3MF_OK && more) {
    NMR::PLib3MFModelResource* raw_res = nullptr;
    check(NMR::lib3mf_resourceiterator_getcurrent(it.get(), &raw_res), path, it.get(), "an object");
    const Owned<NMR::PLib3MFModelResource> res(raw_res);
    auto* mesh = static_cast<NMR::PLib3MFModelMeshObject*>(res.get());
    DWORD nv = 0, nt = 0;
    check(NMR::lib3mf_meshobject_getvertexcount(mesh, &nv), path, mesh, "vertices");
    check(NMR::lib3mf_meshobject_gettrianglecount(mesh, &nt), path, mesh, "triangles");
    std::vector<NMR::MODELMESHVERTEX> v(nv);
    std::vector<NMR::MODELMESHTRIANGLE> t(nt);
    if (nv)
      check(NMR::lib3mf_meshobject_getvertices(mesh, v.data(), nv, nullptr), path, mesh,
            "vertices");
    if (nt)
      check(NMR::lib3mf_meshobject_gettriangleindices(mesh, t.data(), nt, nullptr), path, mesh,
            "triangles");
    TriangleSoup soup;
    for (const auto& x : v)
      soup.vertices.push_back(
          out.unit_mm * Eigen::Vector3d(x.m_fPosition[0], x.m_fPosition[1], x.m_fPosition[2]));
    for (const auto& x : t) {
      for (const DWORD i : x.m_nIndices)
        if (i >= nv) throw InputError(path, "a triangle names a vertex the object does not have");
      soup.triangles.emplace_back(static_cast<int>(x.m_nIndices[0]),
                                  static_cast<int>(x.m_nIndices[1]),
                                  static_cast<int>(x.m_nIndices[2]));
    }
    const std::string name = utf8_of([&](LPSTR b, ULONG n, ULONG* need) {
      return NMR::lib3mf_object_getnameutf8(mesh, b, n, need);
    });
    out.parts.emplace_back(name, build_mesh(soup));
  }
  return out;
}

}  // namespace cranioplan
